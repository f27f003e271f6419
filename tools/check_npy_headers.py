#!/usr/bin/env python3
"""Checks the numpy column of tests/npy_header_test.cpp's table against the numpy installed.

Each case is a .npy header (format 1.0) and what numpy makes of it: "SHAPE DESCR" as np.load
reads the file (with the data the shape needs), or "refused". The C++ test checks that nimbus
accepts a header only where numpy reads it the same; this script keeps the table honest.

Usage: tools/check_npy_headers.py tests/npy_header_test.cpp   (exit 1 on any difference)
"""
import ast
import io
import re
import struct
import sys

import numpy as np

CASE = re.compile(r'^\s*\{("(?:[^"\\]|\\.)*"),\s*("(?:[^"\\]|\\.)*"),?')


def numpy_reads(header: str) -> str:
    head = header.encode("latin-1")
    prefix = b"\x93NUMPY\x01\x00" + struct.pack("<H", len(head)) + head
    try:
        shape, _, dtype = np.lib.format.read_array_header_1_0(io.BytesIO(prefix[8:]))
        count = 1
        for n in shape:
            count *= n
        data = b"\0" * (count * dtype.itemsize) if 0 <= count < 1 << 20 else b""
        a = np.load(io.BytesIO(prefix + data))
    except Exception:  # noqa: BLE001: every way numpy refuses counts as refused
        return "refused"
    return f"{a.shape} {a.dtype.str}"


def main() -> int:
    # A case may span two lines: its header and numpy's verdict are on the first.
    cases = [m for line in open(sys.argv[1], encoding="utf-8") if (m := CASE.match(line))]
    bad = 0
    for m in cases:
        header, expected = ast.literal_eval(m.group(1)), ast.literal_eval(m.group(2))
        got = numpy_reads(header)
        if got != expected:
            print(f"{header!r}: the table says {expected!r}, numpy {np.__version__} {got!r}")
            bad += 1
    print(f"{len(cases)} .npy headers, {bad} read otherwise by numpy {np.__version__}")
    return 1 if bad or not cases else 0


if __name__ == "__main__":
    sys.exit(main())
