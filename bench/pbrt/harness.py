"""What the side-by-side drivers (side_by_side.py, spheres_side_by_side.py) share: the two
renderers' command lines, running a render timed by its CPU time, and reading the images back
(EXR through exr_to_pfm, then PFM)."""

import os
import subprocess
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # Rec. 709 weights


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def nimbus_command(nimbus, scene, exr, spp, seed, threads, stats, overrides):
    cmd = [nimbus, "render", scene, "-o", exr, "--spp", str(spp), "--seed", str(seed),
           "--threads", str(threads), "--quiet", "--stats", stats]
    for o in overrides:
        cmd += ["--set", o]
    return cmd


def pbrt_command(pbrt, scene, exr, spp, seed, threads, stats):
    """pbrt-v4's command line; with stats, its statistics go to the output (the log)."""
    return ([pbrt, "--nthreads", str(threads), "--spp", str(spp), "--seed", str(seed),
             "--outfile", exr, "--quiet"] + (["--stats"] if stats else []) + [scene])


class RenderFailed(Exception):
    def __init__(self, code, cmd, log_tail):
        super().__init__("exit %d: %s" % (code, " ".join(cmd)))
        self.code, self.cmd, self.log_tail = code, cmd, log_tail


def run_timed(cmd, cwd, log_path, tail_chars):
    """Runs cmd with its output to log_path; returns the child's CPU seconds (user + system),
    wall seconds and peak resident MiB. A non-zero exit raises RenderFailed with the last
    tail_chars of the log; a command that cannot start raises OSError."""
    with open(log_path, "wb") as logf:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, cwd=cwd, stdout=logf, stderr=subprocess.STDOUT)
        _, status, ru = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise RenderFailed(code, cmd, open(log_path, errors="replace").read()[-tail_chars:])
    return ru.ru_utime + ru.ru_stime, wall, ru.ru_maxrss / 1024


def read_pfm(path):
    """A colour PFM as float64 (height, width, 3), top row first."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            raise ValueError("%s is not a colour PFM" % path)
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.fromfile(f, dtype="<f4" if scale < 0 else ">f4", count=w * h * 3)
    return data.reshape(h, w, 3)[::-1].astype(np.float64)


def read_exr(exr_to_pfm, exr):
    """An EXR image through the exr_to_pfm converter (its PFM is left beside it)."""
    pfm = exr[:-4] + ".pfm"
    subprocess.run([exr_to_pfm, exr, pfm], check=True)
    return read_pfm(pfm)


def block_sums(x, block):
    """Sums over block x block pixel blocks of an (h, w, 3) image, the edges cut off."""
    h, w, _ = x.shape
    return x[: h // block * block, : w // block * block].reshape(
        h // block, block, w // block, block, 3).sum(axis=(1, 3))
