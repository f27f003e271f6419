"""AOV layers from Python (issue 28, item 4): nimbus.read_exr(path, layer) on the EXR of
`nimbus render --aov`, and tools/exr_to_pfm_layers.py, which splits it into the PFM files that
OIDN's oidnDenoise reads and writes its output back (docs/denoising.md)."""
import os
import subprocess
import sys

import numpy as np
import pytest

import nimbus

SOURCE = os.environ.get("NIMBUS_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("NIMBUS_EXE", os.path.join(SOURCE, "build", "nimbus"))
DEMO = os.path.join(SOURCE, "scenes", "demo.json")
SCRIPT = os.path.join(SOURCE, "tools", "exr_to_pfm_layers.py")


def render(path, *args):
    subprocess.run([EXE, "render", DEMO, "-o", str(path), "-q", "--spp", "2", "--set",
                    "film.width=24", "--set", "film.height=16", *args], check=True)
    return path


def script(*args):
    return subprocess.run([sys.executable, SCRIPT, *map(str, args)], capture_output=True,
                          text=True)


def read_pfm(path):
    """A PFM read here, not by the script: header, little-endian rows bottom to top."""
    kind, size, scale, data = path.read_bytes().split(b"\n", 3)
    width, height = map(int, size.split())
    assert float(scale) == -1.0
    channels = {b"PF": 3, b"Pf": 1}[kind]
    return np.frombuffer(data, "<f4").reshape(height, width, channels)[::-1]


def test_read_exr_reads_each_layer_and_the_colour_is_unchanged(tmp_path):
    exr = render(tmp_path / "aov.exr", "--aov", "albedo,normal,depth,variance")
    for name, channels in [("albedo", 3), ("normal", 3), ("depth", 1), ("variance", 3)]:
        layer = nimbus.read_exr(exr, name)
        assert layer.dtype == np.float32
        assert layer.shape == (16, 24, channels)
    albedo = nimbus.read_exr(exr, "albedo")
    assert albedo.min() >= 0 and albedo.max() <= 1 and albedo.max() > 0
    assert np.linalg.norm(nimbus.read_exr(exr, "normal"), axis=2).max() <= 1 + 1e-6
    assert (nimbus.read_exr(exr, "depth") > 0).all()
    assert np.array_equal(nimbus.read_exr(exr), nimbus.read_exr(render(tmp_path / "plain.exr")))
    with pytest.raises(ValueError,
                       match="no layer \"alpha\" \\(the file's layers: albedo, depth, normal, "
                             "variance\\)"):
        nimbus.read_exr(exr, "alpha")
    with pytest.raises(ValueError, match="the file's layers: none"):
        nimbus.read_exr(tmp_path / "plain.exr", "albedo")
    with pytest.raises(TypeError, match="layer must be a str"):
        nimbus.read_exr(exr, 3)


def test_the_script_splits_the_layers_into_pfm_files_and_back(tmp_path):
    exr = render(tmp_path / "aov.exr", "--aov", "normal,albedo,depth")
    layers = tmp_path / "layers"
    layers.mkdir()
    r = script(exr, layers)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in layers.iterdir()) == ["albedo.pfm", "color.pfm", "depth.pfm",
                                                        "normal.pfm"]
    assert np.array_equal(read_pfm(layers / "color.pfm"), nimbus.read_exr(exr))
    for name in ("albedo", "normal", "depth"):
        assert np.array_equal(read_pfm(layers / f"{name}.pfm"), nimbus.read_exr(exr, name)), name
    # oidnDenoise's output is a PFM like color.pfm: back to an EXR, the same pixels.
    r = script("--back", layers / "color.pfm", tmp_path / "back.exr")
    assert r.returncode == 0, r.stderr
    assert np.array_equal(nimbus.read_exr(tmp_path / "back.exr"), nimbus.read_exr(exr))


def test_the_script_refuses_bad_input_with_one_line(tmp_path):
    exr = render(tmp_path / "aov.exr", "--aov", "albedo")
    (tmp_path / "bad.pfm").write_bytes(b"P6\n2 2\n255\n")
    for args in [(tmp_path / "missing.exr", tmp_path), (exr, tmp_path / "no_such_dir"),
                 ("--back", tmp_path / "bad.pfm", tmp_path / "out.png"), (exr,)]:
        r = script(*args)
        assert r.returncode == 2, args
        assert r.stderr.count("\n") == 1, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["aov.exr", "bad.pfm"]
