#!/usr/bin/python3
"""nimbus against pbrt-v4 on N diffuse spheres over a floor, one thread each.

The scene is tools/bench_scale.py's "objects" scene (N diffuse spheres of albedo 0.7 on a
square grid over a box floor of albedo 0.5, a sun and a sky, 96 x 64 pixels, max depth 4, at
equal image coverage for every N): its objects_scene() writes the nimbus scene, and this
script translates that same scene into pbrt-v4's format:

  - camera: `Scale -1 1 1` (pbrt's LookAt is left-handed, nimbus right-handed), the same
    LookAt and vertical fov (pbrt's fov is the shorter axis', here the vertical one), a box
    pixel filter of one pixel, the "rgb" film writing float EXR;
  - spheres: `Shape "sphere"` per object under its own Translate (AttributeBegin/End), with
    the sphere's radius; the box floor: a 12-triangle mesh;
  - surfaces: "diffuse" with the albedo as a constant spectrum ([300 a 900 a]), as nimbus
    upsamples grey exactly;
  - lights: nimbus's "directional" (irradiance E, direction d) is pbrt's "distant" with
    "rgb L" [E E E] from 0 to d; nimbus's "environment" (radiance L) is a uniform "infinite"
    light with "rgb L" [L L L] (an RGB light of luminance 1 renders as 1 in both);
  - integrator: pbrt "path" with maxdepth = nimbus max_depth (both: at most that many
    scattering events, each with next-event estimation); sampler "zsobol" in both.

For each N, and for each of REPS repetitions, the renderer configurations run one after the
other (nimbus, pbrt-v4, nimbus spectral 4, ... : interleaved, so a slow spell of the shared
machine touches all of them), each at SPP and at 1 spp with --threads 1 / --nthreads 1, seed =
the repetition. The render's CPU time is the process's CPU time (user + system) at SPP less
that at 1 spp (which holds the setup: parsing, object compile / BVH build, image writing);
samples/s = width * height * (SPP - 1) / that time. Rays are the renderers' own counters at
SPP less those at 1 spp: nimbus --stats counters.surface_rays + counters.shadow_rays, pbrt-v4
--stats "Regular ray intersection tests" + "Shadow ray intersection tests" (camera rays are
among the closest-hit queries in both); rays/s = rays / render CPU time. Medians over the
repetitions (of the per-repetition differences). SPP, unless given, is the smallest power of
two (at most 65 536) at which every configuration's render part is at least --min-render
seconds, from calibration runs at 1 spp and at 16 spp, raised x4 (to at most 4096) until the
render part is half of --min-render.

The image means (R, G, B) of the SPP renders, averaged over the repetitions, are printed for
both renderers: a gross mismatch means the scenes differ (exit 1 when any channel differs by
more than --mean-tolerance). EXR is read through bench/pbrt/exr_to_pfm.cpp, built here with
g++ against the system's OpenEXR unless EXR_TO_PFM names a binary.

Usage:
  /usr/bin/python3 bench/pbrt/spheres_side_by_side.py [--pbrt PBRT] [--nimbus NIMBUS]
      [--counts 16,256,4096,65536] [--reps 5] [--spp S] [--min-render 2.0]
      [--modes rgb,spectral4] [--out DIR] [--json FILE] [--mean-tolerance 0.02]

  PBRT, NIMBUS, EXR_TO_PFM may also be given in the environment (arguments win). nimbus
  modes: "rgb" (nimbus's default, as tools/bench_scale.py renders) and "spectral4" (spectral
  mode with 4 wavelengths per path, pbrt-v4's). OUT (default: a new temporary folder) holds
  the scenes, images, logs and stats. Markdown tables go to stdout, progress to stderr.
Exit status: 0 done, 1 a render failed or the image means disagree, 2 bad setup.
"""

import argparse
import ast
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

try:
    import numpy as np
except ImportError:
    print("spheres_side_by_side: numpy is needed (Debian: apt-get install python3-numpy)",
          file=sys.stderr)
    sys.exit(2)

from harness import (LUMINANCE, REPO, RenderFailed, block_sums, log, nimbus_command,
                     pbrt_command, read_exr, run_timed)

BENCH_SCALE = os.path.join(REPO, "tools", "bench_scale.py")
EXR_TO_PFM_SRC = os.path.join(REPO, "bench", "pbrt", "exr_to_pfm.cpp")

MODES = {
    "rgb": ("nimbus rgb", []),
    "spectral4": ("nimbus spectral 4",
                  ['spectrum.mode="spectral"', "spectrum.wavelengths=4"]),
}


def die(msg, code=2):
    print("spheres_side_by_side: " + msg, file=sys.stderr)
    sys.exit(code)


def load_bench_scale():
    """tools/bench_scale.py's functions, without running its main() (the module calls main()
    at the top level): the file's top-level statements but that call, executed as a module."""
    try:
        src = open(BENCH_SCALE).read()
    except OSError as e:
        die("cannot read %s: %s" % (BENCH_SCALE, e.strerror))
    tree = ast.parse(src, BENCH_SCALE)
    tree.body = [s for s in tree.body
                 if not (isinstance(s, ast.Expr) and isinstance(s.value, ast.Call)
                         and isinstance(s.value.func, ast.Name) and s.value.func.id == "main")]
    ns = {"__name__": "bench_scale", "__file__": BENCH_SCALE}
    exec(compile(tree, BENCH_SCALE, "exec"), ns)
    if "objects_scene" not in ns:
        die("%s has no objects_scene()" % BENCH_SCALE)
    return ns


# ---------------------------------------------------------------------------------------------
# nimbus scene -> pbrt-v4 scene


def grey(value, what):
    """A grey colour as one number ([v, v, v] or v)."""
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, list) and len(value) == 3 and value[0] == value[1] == value[2]:
        return float(value[0])
    die("unsupported %s %r (only grey colours are translated)" % (what, value))


def num(x):
    return repr(float(x)) if not float(x).is_integer() else str(int(x))


def vec(v):
    return " ".join(num(x) for x in v)


def box_mesh(lo, hi):
    """12 outward-facing triangles of the box [lo, hi] (as bench/pbrt/marble.pbrt's floor)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    p = [x0, y0, z0, x1, y0, z0, x1, y1, z0, x0, y1, z0,
         x0, y0, z1, x1, y0, z1, x1, y1, z1, x0, y1, z1]
    idx = [0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
           3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5]
    return ('Shape "trianglemesh" "point3 P" [%s]\n      "integer indices" [%s]\n'
            % (vec(p), " ".join(map(str, idx))))


def to_pbrt(scene, image_name):
    """pbrt-v4 text of a nimbus scene made of spheres and boxes with diffuse grey surfaces, a
    directional and an environment light. Anything else is refused (exit 2)."""
    known_top = {"film", "camera", "integrator", "lights", "shapes", "objects"}
    if set(scene) - known_top:
        die("unsupported scene keys %s" % sorted(set(scene) - known_top))
    film, cam, integ = scene["film"], scene["camera"], scene.get("integrator", {})
    if cam.get("type", "perspective") != "perspective":
        die("only perspective cameras are translated")
    up = cam.get("up", [0, 1, 0])
    out = ["# Written by bench/pbrt/spheres_side_by_side.py from tools/bench_scale.py's "
           "objects scene.",
           "Scale -1 1 1  # nimbus is right-handed, pbrt's LookAt left-handed",
           "LookAt %s   %s   %s" % (vec(cam["from"]), vec(cam["to"]), vec(up)),
           'Camera "perspective" "float fov" %s' % num(cam.get("fov", 40)),
           'Film "rgb" "integer xresolution" %d "integer yresolution" %d'
           % (film.get("width", 640), film.get("height", 480)),
           '     "string filename" "%s" "bool savefp16" false' % image_name,
           'PixelFilter "box"',
           'Sampler "zsobol" "integer pixelsamples" %d' % integ.get("spp", 16),
           'Integrator "path" "integer maxdepth" %d' % integ.get("max_depth", 1000),
           "", "WorldBegin", ""]
    for light in scene.get("lights", []):
        if light["type"] == "directional":
            e = grey(light["irradiance"], "irradiance")
            out.append('LightSource "distant" "point3 from" [0 0 0] "point3 to" [%s] '
                       '"rgb L" [%s %s %s]' % (vec(light["direction"]), num(e), num(e), num(e)))
        elif light["type"] == "environment":
            r = grey(light["radiance"], "radiance")
            out.append('LightSource "infinite" "rgb L" [%s %s %s]' % (num(r), num(r), num(r)))
        else:
            die("unsupported light type %r" % light["type"])
    out.append("")
    shapes = scene.get("shapes", {})
    current_albedo = None
    for i, obj in enumerate(scene.get("objects", [])):
        if set(obj) - {"shape", "surface"}:
            die("object %d: unsupported keys %s" % (i, sorted(set(obj) - {"shape", "surface"})))
        surf = obj["surface"]
        if surf.get("type") != "diffuse" or set(surf) - {"type", "albedo"}:
            die("object %d: unsupported surface %r" % (i, surf))
        albedo = grey(surf.get("albedo", 0.5), "albedo")
        shape = obj["shape"]
        if isinstance(shape, str):
            if shape not in shapes:
                die("object %d: unknown shape %r" % (i, shape))
            shape = shapes[shape]
        if "transform" in shape:
            die("object %d: shape transforms are not translated" % i)
        if albedo != current_albedo:
            out.append('Material "diffuse" "spectrum reflectance" [300 %s 900 %s]'
                       % (num(albedo), num(albedo)))
            current_albedo = albedo
        if shape["type"] == "sphere":
            c = shape.get("center", [0, 0, 0])
            out.append('AttributeBegin Translate %s Shape "sphere" "float radius" %s '
                       'AttributeEnd' % (vec(c), num(shape["radius"])))
        elif shape["type"] == "box":
            out.append("AttributeBegin")
            out.append("  " + box_mesh(shape["min"], shape["max"]).rstrip())
            out.append("AttributeEnd")
        else:
            die("object %d: unsupported shape type %r" % (i, shape["type"]))
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------------------------
# running


def run_timed_or_die(cmd, cwd, log_path):
    """harness.run_timed, its failures told as this script's exit statuses."""
    try:
        return run_timed(cmd, cwd, log_path, 1500)
    except RenderFailed as e:
        die("render failed (exit %d): %s\n%s" % (e.code, " ".join(e.cmd), e.log_tail), 1)
    except OSError as e:
        die("cannot run %s: %s" % (cmd[0], e.strerror))


PBRT_COUNTERS = {"Regular ray intersection tests": "surface_rays",
                 "Shadow ray intersection tests": "shadow_rays",
                 "Camera rays traced": "camera_rays"}


def pbrt_counters(log_path):
    found = {}
    for line in open(log_path, errors="replace"):
        for title, key in PBRT_COUNTERS.items():
            m = re.match(r"\s*" + re.escape(title) + r"\s+(\d+)\s*$", line)
            if m:
                found[key] = int(m.group(1))
    return found


class Runner:
    def __init__(self, a, work):
        self.a, self.work = a, work
        self.images = os.path.join(work, "runs")
        os.makedirs(self.images, exist_ok=True)

    def render(self, config, n, spp, seed, tag):
        """One render; returns a dict: cpu, wall, rss, rays (closest-hit + shadow), counters,
        and the image mean when asked (tag without "-1spp")."""
        base = os.path.join(self.images, "%s-n%d-%s" % (config["key"], n, tag))
        exr, log_path = base + ".exr", base + ".log"
        if config["renderer"] == "nimbus":
            stats = base + ".json"
            cmd = nimbus_command(self.a.nimbus, config["scene"][n], exr, spp, seed, 1, stats,
                                 ['integrator.sampler="zsobol"'] + config["overrides"])
        else:
            cmd = pbrt_command(self.a.pbrt, config["scene"][n], exr, spp, seed, 1, True)
        cpu, wall, rss = run_timed_or_die(cmd, self.work, log_path)
        r = {"cpu": cpu, "wall": wall, "rss": rss, "cmd": cmd}
        if config["renderer"] == "nimbus":
            st = json.load(open(stats))
            c = st.get("counters", {})
            r["counters"] = {k: c[k] for k in ("surface_rays", "shadow_rays", "paths") if k in c}
            r["nimbus_samples_per_second"] = st.get("samples_per_second")
        else:
            r["counters"] = pbrt_counters(log_path)
        c = r["counters"]
        r["rays"] = (c["surface_rays"] + c["shadow_rays"]
                     if "surface_rays" in c and "shadow_rays" in c else None)
        img = read_exr(self.a.exr_to_pfm, exr)
        r["mean"] = img.mean(axis=(0, 1)).tolist()
        r["image"] = img
        return r


def block_difference(a, b, block=8):
    """Relative rms and largest difference of the luminance of block x block pixel blocks of
    image b against image a, over the blocks brighter than a tenth of a's brightest: a
    mirrored or shifted scene shows here where the image means may agree."""
    def blocks(x):
        return (block_sums(x, block) / (block * block)) @ LUMINANCE
    la, lb = blocks(a), blocks(b)
    bright = la > 0.1 * la.max()
    rel = (lb - la)[bright] / la[bright]
    return float(np.sqrt((rel ** 2).mean())), float(np.abs(rel).max())


def pow2_at_least(x):
    return 1 << max(0, math.ceil(math.log2(max(x, 1))))


# Calibration renders: 1 spp, then CAL_FIRST_SPP, raised x4 up to CAL_LAST_SPP until the render
# part (the difference) is half of --min-render. Where the set-up dominates (N = 65 536: two
# 1-spp runs 0.18 s apart, 16 spp only 0.09 s above 1 spp) a 16-spp difference is noise; it
# once fell to its floor and calibrated 65 536 spp. MAX_SPP bounds what a bad calibration costs.
CAL_FIRST_SPP, CAL_LAST_SPP, MAX_SPP = 16, 4096, 65536


def calibrate(runner, configs, n, min_render):
    """The smallest power of two (8 to MAX_SPP) at which every configuration's render part is
    1.25 x min_render, from each one's CPU cost per spp."""
    per_spp = []
    for c in configs:
        one = runner.render(c, n, 1, 1, "cal-1spp")["cpu"]
        spp = CAL_FIRST_SPP
        while True:
            part = runner.render(c, n, spp, 1, "cal-%dspp" % spp)["cpu"] - one
            if part >= min_render / 2 or spp >= CAL_LAST_SPP:
                break
            spp *= 4
        per_spp.append(max(part, 1e-3) / (spp - 1))
    return min(MAX_SPP, max(8, pow2_at_least(1 + 1.25 * min_render / min(per_spp))))


def loadavg():
    return " ".join("%.2f" % x for x in os.getloadavg())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pbrt", default=os.environ.get("PBRT"))
    ap.add_argument("--nimbus", default=os.environ.get("NIMBUS"))
    ap.add_argument("--exr-to-pfm", dest="exr_to_pfm", default=os.environ.get("EXR_TO_PFM"))
    ap.add_argument("--counts", default="16,256,4096,65536")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--spp", type=int, default=None,
                    help="samples per pixel of the timed renders (default: calibrated per N)")
    ap.add_argument("--min-render", dest="min_render", type=float, default=2.0,
                    help="seconds of render (SPP less 1 spp) each configuration needs at least")
    ap.add_argument("--modes", default="rgb,spectral4", help="nimbus modes: rgb, spectral4")
    ap.add_argument("--out", default=None)
    ap.add_argument("--json", default=None)
    ap.add_argument("--mean-tolerance", dest="mean_tol", type=float, default=0.02)
    a = ap.parse_args()

    if not a.pbrt:
        die("no pbrt-v4 binary: set PBRT or pass --pbrt")
    if not a.nimbus:
        die("no nimbus binary: set NIMBUS or pass --nimbus")
    for name in ("pbrt", "nimbus"):
        path = getattr(a, name)
        if not (os.path.isfile(path) and os.access(path, os.X_OK)):
            die("%s=%s is not an executable file" % (name.upper(), path))
        setattr(a, name, os.path.realpath(path))
    probe = subprocess.run([a.pbrt, "--help"], capture_output=True, text=True)
    if "--wavefront" not in probe.stdout + probe.stderr:
        die("PBRT=%s does not look like pbrt-v4 (its --help has no --wavefront)" % a.pbrt)
    probe = subprocess.run([a.nimbus, "--version"], capture_output=True, text=True)
    if probe.returncode != 0 or "nimbus" not in probe.stdout + probe.stderr:
        die("NIMBUS=%s does not look like nimbus (--version failed)" % a.nimbus)
    nimbus_version = (probe.stdout + probe.stderr).strip()
    try:
        counts = [int(x) for x in a.counts.split(",")]
    except ValueError:
        die("--counts: comma-separated integers, not %r" % a.counts)
    if not counts or min(counts) < 1 or a.reps < 1 or (a.spp is not None and a.spp < 2):
        die("--counts must be >= 1, --reps >= 1 and --spp >= 2")
    modes = [m for m in a.modes.split(",") if m]
    for m in modes:
        if m not in MODES:
            die("unknown nimbus mode %r (known: %s)" % (m, ", ".join(MODES)))

    work = os.path.abspath(a.out) if a.out else tempfile.mkdtemp(prefix="spheres_sbs_")
    os.makedirs(work, exist_ok=True)
    if not a.exr_to_pfm:
        a.exr_to_pfm = os.path.join(work, "exr_to_pfm")
        if not shutil.which("g++") or not shutil.which("pkg-config"):
            die("g++ and pkg-config are needed to build exr_to_pfm (or set EXR_TO_PFM)")
        flags = subprocess.run(["pkg-config", "--cflags", "--libs", "OpenEXR"],
                               capture_output=True, text=True)
        if flags.returncode != 0:
            die("pkg-config finds no OpenEXR (Debian: apt-get install libopenexr-dev), "
                "or set EXR_TO_PFM")
        b = subprocess.run(["g++", "-O2", "-std=c++17", EXR_TO_PFM_SRC, "-o", a.exr_to_pfm]
                           + flags.stdout.split(), capture_output=True, text=True)
        if b.returncode != 0:
            die("building exr_to_pfm failed: %s" % b.stderr.strip().splitlines()[-1:])
    elif not os.access(a.exr_to_pfm, os.X_OK):
        die("EXR_TO_PFM=%s is not an executable file" % a.exr_to_pfm)

    bs = load_bench_scale()
    configs = [{"key": "nimbus-" + modes[0], "label": MODES[modes[0]][0], "renderer": "nimbus",
                "overrides": MODES[modes[0]][1], "scene": {}} if modes else None,
               {"key": "pbrt", "label": "pbrt-v4", "renderer": "pbrt", "overrides": [],
                "scene": {}}]
    configs = [c for c in configs if c]
    for m in modes[1:]:
        configs.append({"key": "nimbus-" + m, "label": MODES[m][0], "renderer": "nimbus",
                        "overrides": MODES[m][1], "scene": {}})
    runner = Runner(a, work)
    log("work folder: %s" % work)
    log("nimbus: %s (%s); pbrt: %s" % (a.nimbus, nimbus_version, a.pbrt))

    results = {}
    for n in counts:
        scene = bs["objects_scene"](n, False)
        width, height = scene["film"]["width"], scene["film"]["height"]
        nscene = os.path.join(work, "spheres_%d.json" % n)
        pscene = os.path.join(work, "spheres_%d.pbrt" % n)
        with open(nscene, "w") as f:
            json.dump(scene, f)
        with open(pscene, "w") as f:
            f.write(to_pbrt(scene, "spheres_%d.exr" % n))
        for c in configs:
            c["scene"][n] = nscene if c["renderer"] == "nimbus" else pscene
        load_start = loadavg()
        spp = a.spp
        if spp is None:
            spp = calibrate(runner, configs, n, a.min_render)
        log("N = %d: %d spp, %d repetitions (load %s)" % (n, spp, a.reps, load_start))
        runs = {c["key"]: [] for c in configs}
        for rep in range(a.reps):
            for c in configs:
                full = runner.render(c, n, spp, rep + 1, "rep%d" % rep)
                one = runner.render(c, n, 1, rep + 1, "rep%d-1spp" % rep)
                runs[c["key"]].append({"full": full, "one": one})
            log("  repetition %d done (load %s)" % (rep + 1, loadavg()))
        load_end = loadavg()
        row = {"spp": spp, "load_start": load_start, "load_end": load_end, "configs": {}}
        for c in configs:
            rs = runs[c["key"]]
            render_cpu = [r["full"]["cpu"] - r["one"]["cpu"] for r in rs]
            t = statistics.median(render_cpu)
            samples = width * height * (spp - 1)
            rays = [r["full"]["rays"] - r["one"]["rays"] if r["full"]["rays"] is not None
                    and r["one"]["rays"] is not None else None for r in rs]
            rays_per_s = (statistics.median(x / max(y, 1e-9) for x, y in zip(rays, render_cpu))
                          if None not in rays else None)
            row["configs"][c["key"]] = {
                "label": c["label"],
                "render_cpu_s": t,
                "render_cpu_s_all": render_cpu,
                "samples_per_s": statistics.median(samples / max(x, 1e-9) for x in render_cpu),
                "rays_per_s": rays_per_s,
                "rays_per_sample": (statistics.median(rays) / samples
                                    if None not in rays else None),
                "setup_cpu_s": statistics.median(r["one"]["cpu"] for r in rs),
                "wall_s": statistics.median(r["full"]["wall"] for r in rs),
                "peak_mib": statistics.median(r["full"]["rss"] for r in rs),
                "mean": np.mean([r["full"]["mean"] for r in rs], axis=0).tolist(),
                "image": np.mean([r["full"]["image"] for r in rs], axis=0),
                "nimbus_samples_per_second": [r["full"].get("nimbus_samples_per_second")
                                              for r in rs],
                "counters": [r["full"]["counters"] for r in rs],
                "command": rs[0]["full"]["cmd"],
            }
        results[n] = row
        p = row["configs"]["pbrt"]
        for key, cr in row["configs"].items():
            if key == "pbrt":
                continue
            log("  %s: %.4g samples/s, pbrt %.4g: x%.2f" % (
                cr["label"], cr["samples_per_s"], p["samples_per_s"],
                cr["samples_per_s"] / p["samples_per_s"]))

    # Tables
    print("\nnimbus against pbrt-v4, %s spheres over a floor (tools/bench_scale.py objects), "
          "%d x %d pixels, one thread each, medians of %d interleaved repetitions.\n"
          % (", ".join(map(str, counts)), width, height, a.reps))
    nimbus_keys = [c["key"] for c in configs if c["renderer"] == "nimbus"]
    bad = []
    for key in nimbus_keys:
        label = results[counts[0]]["configs"][key]["label"]
        print("### %s against pbrt-v4\n" % label)
        print("| N | spp | nimbus samples/s | pbrt samples/s | nimbus/pbrt | nimbus rays/s | "
              "pbrt rays/s | nimbus/pbrt rays/s | rays/sample nimbus, pbrt | "
              "setup s (1 spp CPU) nimbus, pbrt | peak MiB nimbus, pbrt | load avg start → end |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for n in counts:
            row = results[n]
            nm, pb = row["configs"][key], row["configs"]["pbrt"]
            def f(x, fmt="%.3g"):
                return fmt % x if x is not None else "n/a"
            rr = (nm["rays_per_s"] / pb["rays_per_s"]
                  if nm["rays_per_s"] and pb["rays_per_s"] else None)
            print("| %d | %d | %s | %s | **%.2f** | %s | %s | **%s** | %s, %s | %.2f, %.2f | "
                  "%.0f, %.0f | %s → %s |" % (
                      n, row["spp"], f(nm["samples_per_s"]), f(pb["samples_per_s"]),
                      nm["samples_per_s"] / pb["samples_per_s"], f(nm["rays_per_s"]),
                      f(pb["rays_per_s"]), f(rr, "%.2f"), f(nm["rays_per_sample"], "%.2f"),
                      f(pb["rays_per_sample"], "%.2f"), nm["setup_cpu_s"], pb["setup_cpu_s"],
                      nm["peak_mib"], pb["peak_mib"], row["load_start"], row["load_end"]))
        print()
    print("Image means (R, G, B) of the timed renders, averaged over the repetitions:\n")
    print("| N | renderer | mean R, G, B | vs pbrt-v4 | 8 x 8-pixel blocks' luminance vs "
          "pbrt-v4: rms, max |")
    print("|---|---|---|---|---|")
    for n in counts:
        pbm = np.array(results[n]["configs"]["pbrt"]["mean"])
        pbi = results[n]["configs"]["pbrt"]["image"]
        for key, cr in results[n]["configs"].items():
            m = np.array(cr["mean"])
            rel = (m - pbm) / pbm
            if key != "pbrt" and np.abs(rel).max() > a.mean_tol:
                bad.append((n, cr["label"], rel))
            cr["blocks_rms"], cr["blocks_max"] = block_difference(pbi, cr["image"])
            print("| %d | %s | %.4f, %.4f, %.4f | %s | %s |" % (
                n, cr["label"], *m,
                "" if key == "pbrt" else "%+.2f %%, %+.2f %%, %+.2f %%" % tuple(100 * rel),
                "" if key == "pbrt" else "%.2f %%, %.2f %%" % (100 * cr["blocks_rms"],
                                                               100 * cr["blocks_max"])))
    print()
    for n in counts:
        for cr in results[n]["configs"].values():
            del cr["image"]
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"nimbus": a.nimbus, "nimbus_version": nimbus_version, "pbrt": a.pbrt,
                       "counts": counts, "reps": a.reps, "results": results}, f, indent=1)
    if bad:
        for n, label, rel in bad:
            log("image means differ: N = %d, %s against pbrt-v4 by %s" % (
                n, label, ", ".join("%+.2f %%" % (100 * x) for x in rel)))
        sys.exit(1)


if __name__ == "__main__":
    main()
