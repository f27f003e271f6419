#!/usr/bin/env python3
"""The viewer's time to first image (docs/benchmarks.md, "The viewer"): starts
`nimbus view SCENE --port 0` ROUNDS times per scene, polls its /state every 5 ms and prints the
medians, from the process's start, of: the server listening (the scene loaded and compiled), the
first image (the preview), and the path tracer's first pass (1 spp over the film).

Usage: tools/bench_view.py NIMBUS ROUNDS SCENE... [--threads N]
"""
import json
import re
import statistics
import subprocess
import sys
import time
import urllib.request


def once(nimbus, scene, threads):
    t0 = time.monotonic()
    cmd = [nimbus, "view", scene, "--port", "0"] + (["--threads", str(threads)] if threads else [])
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = p.stdout.readline()
    listening = time.monotonic() - t0
    m = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
    if not m:
        p.kill()
        sys.exit(f"bench_view: {scene}: the viewer did not start: {p.stderr.read().strip()}")
    url = f"http://127.0.0.1:{m.group(1)}/state"
    first = first_pass = None
    while first_pass is None:
        with urllib.request.urlopen(url, timeout=30) as r:
            s = json.load(r)
        now = time.monotonic() - t0
        if first is None and s["has_image"]:
            first = now
        if s["spp"] >= 1 and not s["preview"]:
            first_pass = now
        if now > 600:
            sys.exit(f"bench_view: {scene}: no first pass in 600 s")
        time.sleep(0.005)
    p.send_signal(2)
    p.communicate(timeout=60)
    return listening, first, first_pass, s["width"], s["height"]


def main():
    args = sys.argv[1:]
    threads = 0
    if "--threads" in args:
        i = args.index("--threads")
        threads = int(args[i + 1])
        del args[i:i + 2]
    if len(args) < 3:
        sys.exit(__doc__)
    nimbus, rounds, scenes = args[0], int(args[1]), args[2:]
    print("| scene | film | listening s | first image (preview) s | first pass (1 spp) s |")
    print("|---|---|---|---|---|")
    for scene in scenes:
        runs = [once(nimbus, scene, threads) for _ in range(rounds)]
        med = [statistics.median(r[k] for r in runs) for k in range(3)]
        w, h = runs[0][3], runs[0][4]
        print(f"| {scene} | {w} × {h} | {med[0]:.3f} | {med[1]:.3f} | {med[2]:.3f} |")


if __name__ == "__main__":
    main()
