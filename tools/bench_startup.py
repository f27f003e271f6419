#!/usr/bin/env python3
"""Start-up of the nimbus executable, one build against another (docs/benchmarks.md, "Start-up":
issue 45). For each command, `nimbus --version` and a render of 64x36 pixels at 1 spp of
scenes/demo.json (and of scenes/vdb_cloud.json, which loads the OpenVDB module), runs the new and
the old build in turn, ROUNDS times each, and prints the median wall and CPU (user + system)
seconds of each, their ratio, and the dynamic loader's relocations (LD_DEBUG=statistics).

Usage: tools/bench_startup.py NEW_NIMBUS OLD_NIMBUS [ROUNDS]    (ROUNDS: default 11)
"""
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

new, old = sys.argv[1], sys.argv[2]
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 11
here = os.path.dirname(os.path.abspath(__file__))
out = os.path.join(tempfile.mkdtemp(), "x.png")
small = ["--spp", "1", "--set", "film.width=64", "--set", "film.height=36", "-q", "-o", out]
commands = {
    "--version": ["--version"],
    "render demo.json, 64x36, 1 spp": ["render", os.path.join(here, "..", "scenes", "demo.json")]
    + small,
    "render vdb_cloud.json, 64x36, 1 spp": ["render",
                                            os.path.join(here, "..", "scenes", "vdb_cloud.json")]
    + small,
}


def timed(argv):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def relocations(argv):
    err = subprocess.run(argv, env=dict(os.environ, LD_DEBUG="statistics"),
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True).stderr
    # The parent's count (a VDB scene's reader child prints its own after it).
    m = re.search(r"final number of relocations: (\d+)", err)
    return int(m.group(1)) if m else -1


print(f"{rounds} rounds, new and old in turn; medians")
print("| command | old wall s | new wall s | new/old | old CPU s | new CPU s | old relocations |"
      " new relocations |")
print("|---|---|---|---|---|---|---|---|")
for name, args in commands.items():
    times = {new: [], old: []}
    for exe in (new, old):  # a warm-up each
        timed([exe] + args)
    for _ in range(rounds):
        for exe in (new, old):
            times[exe].append(timed([exe] + args))
    med = {exe: (statistics.median(w for w, _ in t), statistics.median(c for _, c in t))
           for exe, t in times.items()}
    ratio = statistics.median(a[0] / b[0] for a, b in zip(times[new], times[old]))
    print(f"| {name} | {med[old][0]:.3f} | {med[new][0]:.3f} | {ratio:.2f} | {med[old][1]:.3f} |"
          f" {med[new][1]:.3f} | {relocations([old] + args)} | {relocations([new] + args)} |")
