#!/usr/bin/env python3
"""nimbus export-mesh against libfive's dual contouring, OpenVDB's volumeToMesh and CGAL's Delaunay
refinement on the same shapes at the same error (issue 43; docs/benchmarks.md, "Meshes side by
side").

For each shape and error bound E, nimbus meshes with `--error E`; each other mesher meshes at
its coarsest setting, halving from a start, whose mesh measures within E (largest vertex and
face-centroid distance to the exact surface): libfive's min_feature and OpenVDB's voxel size
from a quarter of the shape's box, CGAL's facet distance from E; the one-thread mesh is the one
measured (CGAL's differ by about 1 % from run to run, its parallel ones more). All meshes are
measured by the same tool, mesh_error (bench/mesh_error.cpp: nimbus's exact roots, so the same
yardstick for all), and timed on 1 and 2 threads (the commands' own seconds, meshing and
writing the file; the median of --reps runs, all meshers interleaved in each), with the
process's peak memory (GNU time).

  LIBFIVE_SRC=/path/to/libfive LIBFIVE_BUILD=/path/to/libfive/build \\
    /usr/bin/python3 bench/mesh_side_by_side.py [--nimbus build/nimbus] \\
    [--mesh-error build/mesh_error] [--openvdb build/mesh_openvdb] [--cgal build/mesh_cgal] \\
    [--anchors libfive,openvdb,cgal] [--reps 3] [--errors 0.004,0.001] [--vs OLD_NIMBUS] \\
    [SHAPE...]

LIBFIVE_SRC is a checkout of github.com/libfive/libfive, LIBFIVE_BUILD its CMake build with the
`five` library built (`cmake -DCMAKE_BUILD_TYPE=Release -DBUILD_STUDIO_APP=OFF
-DBUILD_GUILE_BINDINGS=OFF -DBUILD_PYTHON_BINDINGS=OFF -DENABLE_DEBUG=OFF`; Debian's
libeigen3-dev, libboost-dev and libpng-dev). OpenVDB's and CGAL's drivers are nimbus bench
targets built on request (`cmake --build build --target mesh_openvdb mesh_cgal`; mesh_cgal only
where CMake finds CGAL, Debian's libcgal-dev). A mesher that is missing is left out, with a
line on stderr; with none left and no --vs the script exits 0. --vs adds another nimbus binary
(a build from before a change), timed interleaved with --nimbus; `--anchors ""` leaves the
other meshers out. Shapes: sphere, freeform4, cylinder (default: all).
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

# nimbus's side of bench/libfive/mesh_libfive.cpp's shapes, and each shape's box half-width there.
SHAPES = {
    "sphere": ({"type": "sphere", "radius": 1}, 1.1),
    "freeform4": ({"type": "freeform", "base": {"type": "ellipsoid", "radii": [0.95, 0.8, 0.8]},
                   "perturbations": [
                       {"shape": {"type": "sphere", "center": [0.55, 0.45, 0.3], "radius": 0.45}, "weight": 0.8},
                       {"shape": {"type": "sphere", "center": [-0.6, 0.35, -0.2], "radius": 0.4}, "weight": 0.8},
                       {"shape": {"type": "sphere", "center": [0.1, -0.7, 0.5], "radius": 0.5}, "weight": -0.6},
                       {"shape": {"type": "sphere", "center": [0.0, 0.3, 0.75], "radius": 0.35}, "weight": 0.5}]},
                  1.3),
    "cylinder": ({"type": "intersection", "shapes": [
        {"type": "cylinder", "axis": [0, 0, 1], "radius": 0.5},
        {"type": "slab", "normal": [0, 0, 1], "thickness": 1.6}]}, 1.0),
}


def timed(cmd):
    """Runs cmd under GNU time; returns (stdout, stderr without time's line, peak MiB)."""
    r = subprocess.run(["/usr/bin/time", "-f", "peak %M", *cmd], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr.strip()}")
    peak = int(re.search(r"peak (\d+)", r.stderr).group(1)) / 1024
    return r.stdout, r.stderr, peak


def measure(args, scene, mesh):
    out = subprocess.run([args.mesh_error, scene, mesh, "--samples", "2000"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)


def run_nimbus(args, scene, error, threads, mesh, nimbus):
    _, err, peak = timed([nimbus, "export-mesh", scene, "-o", mesh, "--error", str(error),
                          "--threads", str(threads)])
    return float(re.search(r" in ([0-9.]+) s ->", err).group(1)), peak


class Anchor:
    """Another mesher: a command `exe FIRST SETTING THREADS OUT.stl` that prints its seconds as
    JSON (FIRST: the shape's name for libfive, the staged scene for nimbus's drivers), the
    setting's name, and its start for a shape of box half-width `half` at error bound E."""

    def __init__(self, name, exe, setting, start, by_scene):
        self.name, self.exe, self.setting, self.start, self.by_scene = (
            name, exe, setting, start, by_scene)

    def run(self, shape, scene, value, threads, mesh):
        out, _, peak = timed([self.exe, scene if self.by_scene else shape, repr(value),
                              str(threads), mesh])
        return json.loads(out)["seconds"], peak


def anchors(args, work):
    """The other meshers asked for and present, each with a line on stderr where it is not."""
    found = []
    for name in [a for a in args.anchors.split(",") if a]:
        if name == "libfive":
            src, build = os.environ.get("LIBFIVE_SRC"), os.environ.get("LIBFIVE_BUILD")
            if not src or not build:
                print("mesh_side_by_side: libfive left out: set LIBFIVE_SRC and LIBFIVE_BUILD "
                      "(a libfive checkout and its build)", file=sys.stderr)
                continue
            lib = os.path.join(build, "libfive", "src")
            exe = os.path.join(work, "mesh_libfive")
            # libfive's own flags: -march=native changes Eigen's alignment, and so the objects'
            # layout.
            subprocess.run(["g++", "-O3", "-march=native", "-DEIGEN_NO_DEBUG", "-std=c++17",
                            os.path.join(HERE, "libfive", "mesh_libfive.cpp"),
                            "-I", os.path.join(src, "libfive", "include"),
                            "-I", "/usr/include/eigen3", "-L", lib, "-lfive",
                            f"-Wl,-rpath,{lib}", "-o", exe], check=True)
            found.append(Anchor("libfive", exe, "min_feature", lambda half, e: 2 * half / 4,
                                False))
        elif name in ("openvdb", "cgal"):
            exe = getattr(args, name)
            if not os.access(exe, os.X_OK):
                print(f"mesh_side_by_side: {name} left out: no {exe} (cmake --build build "
                      f"--target mesh_{name})", file=sys.stderr)
                continue
            if name == "openvdb":
                found.append(Anchor("OpenVDB", exe, "voxel", lambda half, e: 2 * half / 4, True))
            else:
                found.append(Anchor("CGAL", exe, "facet_distance", lambda half, e: e, True))
        else:
            raise SystemExit(f"mesh_side_by_side: unknown mesher {name} (libfive, openvdb, cgal)")
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nimbus", default="build/nimbus")
    ap.add_argument("--mesh-error", default="build/mesh_error")
    ap.add_argument("--openvdb", default="build/mesh_openvdb")
    ap.add_argument("--cgal", default="build/mesh_cgal")
    ap.add_argument("--anchors", default="libfive,openvdb,cgal",
                    help="the other meshers, comma-separated (\"\": none)")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--errors", default="0.004,0.001")
    ap.add_argument("--out", default=None, help="work folder (default: a temporary one)")
    ap.add_argument("--vs", default=None, metavar="NIMBUS",
                    help="another nimbus binary (a before), timed interleaved with --nimbus")
    ap.add_argument("shapes", nargs="*", default=list(SHAPES))
    args = ap.parse_args()
    work = args.out or tempfile.mkdtemp(prefix="nimbus-meshes-")
    os.makedirs(work, exist_ok=True)
    others = anchors(args, work)
    if not others and not args.vs:
        print("mesh_side_by_side: skipped: no other mesher and no --vs", file=sys.stderr)
        return 0
    print("| shape | E | mesher | setting | triangles | vertex error | face error | Hausdorff "
          "(samples) | 1 thread (s) | 2 threads (s) | peak memory |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for shape in args.shapes:
        desc, half = SHAPES[shape]
        scene = os.path.join(work, f"{shape}.json")
        with open(scene, "w") as f:
            json.dump({"camera": {"from": [0, 0, 5], "to": [0, 0, 0]},
                       "objects": [{"shape": desc, "surface": {"type": "diffuse"}}]}, f)
        for error in (float(e) for e in args.errors.split(",")):
            mesh = os.path.join(work, f"{shape}-nimbus.stl")
            # Each other mesher's coarsest setting within E, and its one-thread mesh's measure.
            settings, measured = [], []
            for a in others:
                value = a.start(half, error)
                amesh = os.path.join(work, f"{shape}-{a.name}.stl")
                while True:
                    a.run(shape, scene, value, 1, amesh)
                    m = measure(args, scene, amesh)
                    if max(m["vertex_error"], m["face_error"]) <= error or value < error / 64:
                        break
                    value /= 2
                settings.append(value)
                measured.append(m)
            # Timed interleaved: the meshers take turns within each repetition.
            vmesh = os.path.join(work, f"{shape}-vs.stl")
            times, vtimes = {1: [], 2: []}, {1: [], 2: []}
            atimes = [{1: [], 2: []} for _ in others]
            peak = vpeak = 0
            apeak = [0.0 for _ in others]
            for _ in range(args.reps):
                for threads in (1, 2):
                    if args.vs:
                        t, p = run_nimbus(args, scene, error, threads, vmesh, args.vs)
                        vtimes[threads].append(t)
                        vpeak = max(vpeak, p)
                    t, p = run_nimbus(args, scene, error, threads, mesh, args.nimbus)
                    times[threads].append(t)
                    peak = max(peak, p)
                    for i, a in enumerate(others):
                        t, p = a.run(shape, scene, settings[i], threads,
                                     os.path.join(work, f"{shape}-{a.name}-timed.stl"))
                        atimes[i][threads].append(t)
                        apeak[i] = max(apeak[i], p)
            rows = [("nimbus", f"--error {error:g}", measure(args, scene, mesh), times, peak)]
            if args.vs:
                rows.insert(0, ("nimbus (--vs)", f"--error {error:g}", measure(args, scene, vmesh),
                                vtimes, vpeak))
            for i, a in enumerate(others):
                rows.append((a.name, f"{a.setting} {settings[i]:.3g}", measured[i], atimes[i],
                             apeak[i]))
            for name, setting, r, ts, pk in rows:
                print(f"| {shape} | {error:g} | {name} | {setting} | {r['triangles']:,} "
                      f"| {r['vertex_error']:.2g} | {r['face_error']:.2g} | {r['hausdorff']:.2g} "
                      f"| {statistics.median(ts[1]):.3f} | {statistics.median(ts[2]):.3f} "
                      f"| {pk:.0f} MiB |", flush=True)
    return 0

if __name__ == "__main__":
    sys.exit(main())
