#!/usr/bin/python3
"""Manifold next-event estimation at equal time (issue 41), and its cost where it does not apply.

Efficiency (default): per scene, renders with integrator.manifold on and off, REPS times each
(seeds 1..REPS, interleaved), at SPP samples per pixel on THREADS threads, against a reference
of REF_SPP samples per pixel (manifold on, seed 977, cached in OUT keyed by the scene's text and
the options). Prints per configuration the mean MSE over pixels and channels, the median CPU
seconds (user + system) of the process, and the efficiency 1 / (MSE * time). --mask-above V also
gives the MSE over the pixels whose reference stays below V in every channel: a sun's mirror
image in a glass surface, which the camera sees directly and which no light-sampling technique
samples, is then left out (it dominates every MSE alike).

--compare SETTING compares a boolean setting true against false instead (the walk on in both,
and the reference made with it true), e.g. integrator.manifold_area_caustics.

Timing (--vs OTHER_NIMBUS): per scene, the two binaries render the same scene with its own
settings, REPS times each, interleaved, and the script prints the median CPU seconds of each and
the median of the pairwise ratios (this binary / OTHER).

  /usr/bin/python3 bench/manifold_efficiency.py [--nimbus build/nimbus] [--spp 16]
      [--ref-spp 4096] [--reps 4] [--threads 2] [--mask-above V] [--set KEY=VALUE ...]
      [--compare SETTING] [--vs OTHER_NIMBUS] SCENE...

Exit status: 0 done, 2 bad arguments or a render that failed.
"""

import argparse
import hashlib
import os
import statistics
import subprocess
import sys

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print("manifold_efficiency: " + msg, file=sys.stderr)
    sys.exit(2)


def run(cmd):
    """Runs cmd; returns its CPU seconds (user + system of the child)."""
    before = os.times()
    p = subprocess.run(cmd, capture_output=True, text=True)
    after = os.times()
    if p.returncode != 0:
        fail("exit %d: %s\n%s" % (p.returncode, " ".join(cmd), p.stderr[-2000:]))
    return (after.children_user - before.children_user) + (after.children_system -
                                                           before.children_system)


def read_exr(path):
    sys.path.insert(0, os.path.join(REPO, "build", "python"))
    try:
        import nimbus
    except ImportError:
        fail("the nimbus Python module is needed to read EXRs (build it: cmake --build build)")
    return np.asarray(nimbus.read_exr(path), dtype=np.float64)[..., :3]


def render(a, scene, out, spp, seed, sets, nimbus=None):
    cmd = [nimbus or a.nimbus, "render", scene, "-o", out, "--spp", str(spp), "--seed", str(seed),
           "--threads", str(a.threads), "--quiet"]
    for s in a.set + sets:
        cmd += ["--set", s]
    return run(cmd)


def efficiency(a, scene):
    text = open(scene, "rb").read()
    key = hashlib.sha256(text + repr((a.ref_spp, a.set) + ((a.compare,) if a.compare else ())).encode()).hexdigest()[:16]
    ref_path = os.path.join(a.out, "ref-%s.exr" % key)
    if not os.path.exists(ref_path):
        render(a, scene, ref_path, a.ref_spp, 977, ["integrator.manifold=true"] +
               (["%s=true" % a.compare] if a.compare else []))
    ref = read_exr(ref_path)
    mask = ref.max(axis=2) < a.mask_above if a.mask_above else None
    setting = a.compare or "integrator.manifold"
    configs = [("%s on" % setting.split(".")[-1], ["%s=true" % setting]),
               ("%s off" % setting.split(".")[-1], ["%s=false" % setting])]
    res = {label: ([], [], []) for label, _ in configs}
    for rep in range(a.reps):
        for label, sets in configs:
            out = os.path.join(a.out, "eff.exr")
            t = render(a, scene, out, a.spp, rep + 1, sets)
            err = (read_exr(out) - ref) ** 2
            res[label][0].append(err.mean())
            res[label][1].append(t)
            res[label][2].append(err[mask].mean() if mask is not None else err.mean())
    print("%s: %d spp, reference %d spp, %d reps, %d threads%s" %
          (os.path.relpath(scene, REPO), a.spp, a.ref_spp, a.reps, a.threads,
           ", %d pixels masked" % (~mask).sum() if mask is not None else ""))
    for label, _ in configs:
        mse, t = statistics.mean(res[label][0]), statistics.median(res[label][1])
        line = "  %-13s MSE %.4g  CPU %.3f s  efficiency %.4g" % (label, mse, t, 1 / (mse * t))
        if mask is not None:
            m = statistics.mean(res[label][2])
            line += "   masked: MSE %.4g  efficiency %.4g" % (m, 1 / (m * t))
        print(line, flush=True)


def timing(a, scene):
    out = os.path.join(a.out, "timing.exr")
    mine, other, ratios = [], [], []
    for rep in range(a.reps):
        x = render(a, scene, out, a.spp, rep + 1, [])
        y = render(a, scene, out, a.spp, rep + 1, [], nimbus=a.vs)
        mine.append(x)
        other.append(y)
        ratios.append(x / y)
    print("%s: %d spp, %d reps, %d threads: CPU %.3f s (this) against %.3f s (other), "
          "median ratio %.3f (min %.3f, max %.3f)" %
          (os.path.relpath(scene, REPO), a.spp, a.reps, a.threads, statistics.median(mine),
           statistics.median(other), statistics.median(ratios), min(ratios), max(ratios)),
          flush=True)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scenes", nargs="+")
    p.add_argument("--nimbus", default=os.path.join(REPO, "build", "nimbus"))
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--reps", type=int, default=4)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--mask-above", type=float, default=0)
    p.add_argument("--set", action="append", default=[])
    p.add_argument("--vs", help="time this nimbus binary against another one")
    p.add_argument("--compare", metavar="SETTING",
                   help="compare a boolean setting true against false (with the walk on) "
                        "instead of integrator.manifold on against off; one reference, made true")
    p.add_argument("--out", default=os.path.join(REPO, "build", "manifold-efficiency"))
    a = p.parse_args()
    if a.spp < 1 or a.ref_spp < 1 or a.reps < 1 or a.threads < 1:
        fail("--spp, --ref-spp, --reps and --threads must be at least 1")
    for exe in [a.nimbus] + ([a.vs] if a.vs else []):
        if not os.access(exe, os.X_OK):
            fail("%s is not an executable nimbus binary" % exe)
    for s in a.scenes:
        if not os.path.isfile(s):
            fail("%s: no such scene file" % s)
    os.makedirs(a.out, exist_ok=True)
    for s in a.scenes:
        (timing if a.vs else efficiency)(a, os.path.abspath(s))


if __name__ == "__main__":
    main()
