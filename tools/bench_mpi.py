#!/usr/bin/env python3
"""CPU time per sample of nimbus render in one process and on MPI ranks (docs/benchmarks.md,
"MPI and checkpoints"). Runs the configurations interleaved, ROUNDS times, and prints the median
CPU time (user + system of every process, mpirun's included) and wall time per configuration.

Usage: tools/bench_mpi.py NIMBUS SCENE SPP ROUNDS
"""
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

nimbus, scene, spp, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
mpirun = ["mpirun", "-q", "--oversubscribe", "--bind-to", "none"]
configs = {
    "1 process x 2 threads": [nimbus],
    "1 process x 1 thread": [nimbus],
    "1 process x 2 threads, job (--checkpoint)": [nimbus],
    "2 ranks x 1 thread": mpirun + ["-np", "2", nimbus],
}
threads = {"1 process x 2 threads": 2, "1 process x 1 thread": 1,
           "1 process x 2 threads, job (--checkpoint)": 2, "2 ranks x 1 thread": 1}
results = {name: [] for name in configs}
out = tempfile.mkdtemp()
for r in range(rounds):
    for name, prefix in configs.items():
        args = prefix + ["render", scene, "-q", "--spp", str(spp), "--threads",
                         str(threads[name]), "-o", f"{out}/x.exr", "--stats", f"{out}/s.json"]
        if "checkpoint" in name:
            args += ["--checkpoint", f"{out}/c.nck"]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.monotonic()
        subprocess.run(args, env=env, check=True)
        wall = time.monotonic() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        stats = json.load(open(f"{out}/s.json"))
        film, spp = stats["settings"]["film"], stats["settings"]["integrator"]["spp"]
        samples = film["width"] * film["height"] * spp
        results[name].append((cpu / samples * 1e6, wall, stats.get("mpi")))
for name, runs in results.items():
    cpu = statistics.median(x[0] for x in runs)
    wall = statistics.median(x[1] for x in runs)
    print(f"{name:44s} CPU {cpu:7.3f} us/sample (runs: "
          + ", ".join(f"{x[0]:.3f}" for x in runs) + f"), wall {wall:.2f} s")
    if runs[0][2]:
        print("    samples_per_rank:", [x[2]["samples_per_rank"] for x in runs])
