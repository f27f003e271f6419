#!/usr/bin/env python3
"""Splits the EXR of `nimbus render --aov ...` into PFM files, the format of Intel Open Image
Denoise's oidnDenoise, and turns oidnDenoise's output back into an EXR or PNG
(docs/denoising.md).

Usage:
  exr_to_pfm_layers.py RENDER.exr DIR     writes DIR/color.pfm and DIR/NAME.pfm for each AOV
                                          layer the EXR holds (albedo, normal, depth, variance)
  exr_to_pfm_layers.py --back IN.pfm OUT  writes the PFM's pixels to OUT (.exr or .png)

Needs the nimbus Python package (docs/python.md), e.g.
PYTHONPATH=build/python /usr/bin/python3 tools/exr_to_pfm_layers.py render.exr layers
Files are written atomically. Bad input: one line on stderr and exit 2.
"""
import os
import sys

import numpy as np

import nimbus

AOVS = ("albedo", "normal", "depth", "variance")


def write_pfm(path, array):
    """A (height, width, 3) or (height, width, 1) float array as a little-endian PFM, whose rows
    run bottom to top."""
    height, width, channels = array.shape
    header = f"{'PF' if channels == 3 else 'Pf'}\n{width} {height}\n-1.0\n".encode()
    temp = f"{path}.tmp-{os.getpid()}"
    with open(temp, "wb") as f:
        f.write(header)
        f.write(np.ascontiguousarray(array[::-1], dtype="<f4").tobytes())
    os.replace(temp, path)


def read_pfm(path):
    """A PFM's pixels as a float32 array (height, width, 3), top row first; a one-channel PFM is
    repeated into three."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind not in (b"PF", b"Pf"):
            raise ValueError(f"{path}: not a PFM file")
        try:
            width, height = (int(v) for v in f.readline().split())
            scale = float(f.readline())
        except ValueError:
            raise ValueError(f"{path}: a PFM header without its size and scale") from None
        channels = 3 if kind == b"PF" else 1
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    if data.size != width * height * channels:
        raise ValueError(f"{path}: {data.size} values, a {width}x{height} PFM holds "
                         f"{width * height * channels}")
    image = data.reshape(height, width, channels)[::-1].astype(np.float32)
    return np.repeat(image, 3, axis=2) if channels == 1 else image


def split(exr, out_dir):
    if not os.path.isdir(out_dir):
        raise ValueError(f"{out_dir}: not a directory")
    written = [os.path.join(out_dir, "color.pfm")]
    write_pfm(written[0], nimbus.read_exr(exr))
    for name in AOVS:
        try:
            layer = nimbus.read_exr(exr, name)
        except ValueError:
            continue  # not asked for in this render
        written.append(os.path.join(out_dir, f"{name}.pfm"))
        write_pfm(written[-1], layer)
    return written


def main(argv):
    try:
        if len(argv) == 3 and argv[0] == "--back":
            nimbus.write_image(argv[2], read_pfm(argv[1]))
            return 0
        if len(argv) != 2 or argv[0].startswith("-"):
            raise ValueError("usage: exr_to_pfm_layers.py RENDER.exr DIR, or --back IN.pfm OUT")
        for path in split(argv[0], argv[1]):
            print(path)
        return 0
    except (OSError, ValueError, RuntimeError) as e:
        print(f"exr_to_pfm_layers.py: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
