"""F12 in Blender against `nimbus render` of the exported file (docs/benchmarks.md, "Blender").

    /usr/bin/python3 bench/blender_f12.py [--blend scenes/blender/sculpture.blend] [--percent 50]
        [--spp 16] [--reps 5] [--exe build/nimbus]

Each repetition, interleaved: one Blender process opens the .blend, exports it and renders it
with F12 (timed inside Blender, around bpy.ops.render.render; the time to the first pixels is
the engine's own report, from the start of its render call); then `nimbus render` renders the
exported file with the same samples (wall time of the process). Prints the medians and the
ratio F12 / nimbus render. Blender's own start-up is not counted.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import tempfile
import time

INSIDE = r'''
import bpy, sys, time, json, addon_utils
args = sys.argv[sys.argv.index("--") + 1:]
addon_utils.enable("nimbus_blender", default_set=True)
scene = bpy.context.scene
scene.render.engine = "NIMBUS"
scene.render.resolution_percentage = int(args[1])
scene.nimbus.spp = int(args[2])
scene.nimbus.noise_target = 0.0
bpy.ops.export_scene.nimbus(filepath=args[0] + "/scene.json")
start = time.monotonic()
bpy.ops.render.render()
print("F12_SECONDS", time.monotonic() - start)
'''


def main():
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--blend", default=os.path.join(here, "scenes", "blender", "sculpture.blend"))
    p.add_argument("--percent", type=int, default=50)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--exe", default=os.path.join(here, "build", "nimbus"))
    a = p.parse_args()
    build = os.path.dirname(os.path.abspath(a.exe))
    env = dict(os.environ, BLENDER_USER_SCRIPTS=os.path.join(build, "blender"))
    f12, first, cli = [], [], []
    with tempfile.TemporaryDirectory() as folder:
        script = os.path.join(folder, "inside.py")
        with open(script, "w") as f:
            f.write(INSIDE)
        for rep in range(a.reps):
            run = subprocess.run(["blender", "-b", a.blend, "--python-exit-code", "1", "-P", script,
                                  "--", folder, str(a.percent), str(a.spp)],
                                 env=env, capture_output=True, text=True, check=True)
            f12.append(float(re.search(r"F12_SECONDS (\S+)", run.stdout).group(1)))
            first.append(float(re.search(r"first pixels after (\S+) s", run.stdout).group(1)))
            start = time.monotonic()
            subprocess.run([a.exe, "render", os.path.join(folder, "scene.json"), "-q", "-o",
                            os.path.join(folder, "cli.exr")], check=True)
            cli.append(time.monotonic() - start)
            print(f"rep {rep}: F12 {f12[-1]:.3f} s (first pixels {first[-1]:.3f} s), "
                  f"nimbus render {cli[-1]:.3f} s", flush=True)
    m = {k: statistics.median(v) for k, v in (("f12", f12), ("first", first), ("cli", cli))}
    print(json.dumps({"blend": a.blend, "percent": a.percent, "spp": a.spp, "reps": a.reps,
                      "f12_seconds": m["f12"], "first_pixels_seconds": m["first"],
                      "nimbus_render_seconds": m["cli"], "ratio": m["f12"] / m["cli"]}, indent=1))


if __name__ == "__main__":
    main()
