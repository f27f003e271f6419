"""The Blender add-on (python/nimbus_blender, docs/blender.md), run in Debian's Blender headless:
each test runs a case of in_blender.py in a Blender process, then checks what it wrote with the
nimbus module and the command line. Without Blender the tests are skipped, with the reason."""
import json
import os
import shutil
import subprocess

import numpy as np
import pytest

import nimbus

BLENDER = shutil.which("blender")
pytestmark = pytest.mark.skipif(BLENDER is None,
                                reason="Blender is not installed (tools/setup.sh installs it)")
HERE = os.path.dirname(os.path.abspath(__file__))
EXE = os.environ.get("NIMBUS_EXE", "build/nimbus")
SOURCE = os.environ.get("NIMBUS_SOURCE_DIR", os.path.dirname(os.path.dirname(HERE)))
BUILD = os.path.dirname(os.path.abspath(EXE))


def blender(case, out, *args):
    """Runs a case in Blender; returns its result.json and its output (for the reports)."""
    env = dict(os.environ, BLENDER_USER_SCRIPTS=os.path.join(BUILD, "blender"))
    run = subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1",
                          "-P", os.path.join(HERE, "in_blender.py"), "--", case, str(out), *args],
                         env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    with open(os.path.join(out, "result.json")) as f:
        return json.load(f), run.stdout + run.stderr


def cli_render(scene, out, *args):
    subprocess.run([EXE, "render", str(scene), "-q", "-o", str(out), *args], check=True)
    return nimbus.read_exr(str(out))


def test_metaballs_are_blenders_field_exactly(tmp_path):
    """At 10^5 random points away from the surface, the exported free form's sign is that of
    Blender's field minus its threshold, the field computed from the elements with Blender's own
    matrices; and Blender's own tessellation lies on the free form's surface."""
    result, _ = blender("metaballs", tmp_path)
    with open(tmp_path / "scene.json") as f:
        document = json.load(f)
    shape = nimbus.Shape("Blob", shapes=document["shapes"])
    points = np.load(tmp_path / "points.npy")
    field = np.load(tmp_path / "field.npy") - result["threshold"]
    f = shape.values(points)
    away = np.abs(field) > 1e-6
    assert away.sum() > 99000
    inside = field > 0
    assert 2000 < inside.sum() < 98000   # both sides are sampled
    assert np.array_equal(f[away] > 0, field[away] > 0)
    # F is the field minus the threshold, so the values agree too, to float32's rounding.
    np.testing.assert_allclose(f, field, rtol=0, atol=1e-5 * np.abs(field).max())
    # Blender's marching-cubes vertices lie on the surface: within a small fraction of its cell.
    vertices = np.load(tmp_path / "vertices.npy")
    assert len(vertices) > 1000
    h = 1e-5
    gradient = np.stack([(shape.values(vertices + h * e) - shape.values(vertices - h * e)) / (2 * h)
                         for e in np.eye(3)], axis=1)
    distance = np.abs(shape.values(vertices)) / np.linalg.norm(gradient, axis=1)
    assert distance.max() < 0.01 * result["resolution"]   # measured: 0.0053


def test_f12_gives_the_command_lines_pixels_and_export_is_repeatable(tmp_path):
    blender("round_trip", tmp_path)
    result, _ = blender("export_again", tmp_path)
    first = (tmp_path / "first.json").read_bytes()
    assert first == (tmp_path / "second.json").read_bytes()
    f12 = nimbus.read_exr(str(tmp_path / "f12.exr"))
    cli = cli_render(tmp_path / "first.json", tmp_path / "cli.exr")
    assert f12.shape == cli.shape == (36, 48, 3)
    assert np.array_equal(f12, cli)
    assert f12.mean() > 0.05
    document = json.loads(first)
    assert document["integrator"]["spp"] == 6 and document["integrator"]["seed"] == 3
    assert document["objects"][0]["surface"]["type"] == "dielectric"   # the subsurface marble
    ok, message = result["export_over_blend"]
    assert not ok and "is an input of this scene" in message and "scene.blend" in message
    assert result["leftover_temporary_files"] == []


def centroid(image, x, y, radius=5):
    """The brightness-weighted centre of the dot near (x, y), in pixel units (0 at the left
    edge, as world_to_camera_view's x times the width)."""
    h, w, _ = image.shape
    lum = image.sum(axis=2)
    x0, x1 = max(int(x) - radius, 0), min(int(x) + radius + 1, w)
    y0, y1 = max(int(y) - radius, 0), min(int(y) + radius + 1, h)
    patch = lum[y0:y1, x0:x1]
    ys, xs = np.mgrid[y0:y1, x0:x1]
    total = patch.sum()
    assert total > 0, f"no dot near ({x:.1f}, {y:.1f})"
    return (xs * patch).sum() / total + 0.5, (ys * patch).sum() / total + 0.5


def test_camera_framing_is_blenders_projection(tmp_path):
    """Perspective and orthographic cameras, each sensor fit, landscape and portrait, at 50 %:
    small emissive balls appear where Blender projects their centres, within 0.25 pixels."""
    result, _ = blender("camera", tmp_path)
    assert len(result["configs"]) == 6
    for config in result["configs"]:
        image = nimbus.read_exr(config["image"])
        assert image.shape == (config["height"], config["width"], 3)
        for px, py, depth in config["projected"]:
            x, y = px * config["width"], (1 - py) * config["height"]
            cx, cy = centroid(image, x, y)
            assert abs(cx - x) < 0.25 and abs(cy - y) < 0.25, (config["kind"], config["fit"], x, y,
                                                              cx, cy)


def test_light_power_is_cycles(tmp_path):
    """Point (radius 0 and 0.25), sun and spot of the same power over a white diffuse floor:
    nimbus's pixels are Cycles' within 1 % (both nearly noiseless: direct light only)."""
    result, _ = blender("lights", tmp_path)
    for light in result["lights"]:
        ours = nimbus.read_exr(light["nimbus"]).mean(axis=(0, 1))
        cycles = nimbus.read_exr(light["cycles"]).mean(axis=(0, 1))
        assert ours[0] > 0.1
        np.testing.assert_allclose(ours, cycles, rtol=0.01, err_msg=str(light))


def test_volume_emission_is_cycles(tmp_path):
    """An absorbing slab's emission (a colour times a strength, then a 2 500 K blackbody at full
    intensity) against Cycles' render of it: within 0.3 % (measured: 10⁻⁵, and 0.12 % in the
    blackbody's blue). The slab is optically thick (depth 11), so both show e / sigma_a whatever
    their surfaces (nimbus's exact one, Cycles' marching cubes); Cycles' blackbody colours are a
    fit to Planck's law, nimbus's its projection."""
    result, _ = blender("volume_emission", tmp_path)
    for volume in result["volumes"]:
        ours = nimbus.read_exr(volume["nimbus"]).mean(axis=(0, 1))
        cycles = nimbus.read_exr(volume["cycles"]).mean(axis=(0, 1))
        assert ours.max() > 0.02
        np.testing.assert_allclose(ours, cycles, rtol=0.003, err_msg=str(volume))


def test_glowing_vdb_fire_is_cycles(tmp_path):
    """A VDB flame that only emits, its blackbody from the temperature grid (emission per unit
    length under the Stefan-Boltzmann law), against Cycles' render of it."""
    vdb = os.path.join(SOURCE, "scenes", "vdb", "vdb_fire.vdb")
    result, output = blender("fire", tmp_path, vdb)
    document = json.loads((tmp_path / "fire.json").read_text())
    glow = document["media"]["Fire"]["emission_per_length"]
    assert glow["file"] == vdb and glow["grid"] == "temperature"
    assert glow["law"] == "stefan-boltzmann" and glow["temperature_scale"] == 1
    assert "left out" not in output
    ours = nimbus.read_exr(result["fire"]["nimbus"]).mean(axis=(0, 1))
    cycles = nimbus.read_exr(result["fire"]["cycles"]).mean(axis=(0, 1))
    assert ours.max() > 0.01
    # Cycles' blackbody colours are a fit (its blue is negative here), nimbus's Planck's law.
    np.testing.assert_allclose(ours, cycles, rtol=0.05, atol=0.02 * cycles.max(),
                               err_msg=str(result["fire"]))


def test_world_colour_and_strength(tmp_path):
    result, output = blender("world", tmp_path)
    image = nimbus.read_exr(str(tmp_path / "world.exr"))
    np.testing.assert_allclose(image, np.broadcast_to(result["expected"], image.shape), rtol=1e-6)
    assert "the Background node's Color input is linked; its own value is used" in output


def test_vdb_volume_object(tmp_path):
    vdb = os.path.join(SOURCE, "scenes", "vdb", "vdb_cloud.vdb")
    result, _ = blender("volume", tmp_path, vdb)
    document = json.loads((tmp_path / "scene.json").read_text())
    medium = document["media"]["Cloud"]
    assert medium["density"]["file"] == vdb and medium["density"]["grid"] == "density"
    # Cycles' Principled Volume: sigma_s = density colour, sigma_a = density (1 - colour)
    # (1 - sqrt(absorption colour)).
    np.testing.assert_allclose(medium["sigma_s"], [3.6, 3.2, 2.8], rtol=1e-6)
    np.testing.assert_allclose(medium["sigma_a"], [0.2, 0.4, 0.6], rtol=1e-6)
    # The holding box, moved as the object is, holds the grid's world bounds.
    box = nimbus.Shape("Cloud", shapes=document["shapes"])
    corners = np.array(result["world_corners"])
    assert (box.values(corners * 0.999 + corners.mean(axis=0) * 0.001) > 0).all()
    f12 = nimbus.read_exr(str(tmp_path / "f12.exr"))
    cli = cli_render(tmp_path / "scene.json", tmp_path / "cli.exr")
    assert np.array_equal(f12, cli)
    # The cloud is there: pixels brighter or darker than the sky in the corner.
    assert np.abs(f12 - f12[0, 0]).max() > 0.2


def test_bad_input_gives_one_line_each_and_blender_goes_on(tmp_path):
    result, output = blender("bad_input", tmp_path)
    warnings = result["warnings"]
    assert any(w.startswith('object "Cube": a mesh is left out') for w in warnings)
    assert any(w.startswith('object "BezierCurve": a curve object is left out') for w in warnings)
    assert any('element 1 (capsule) is not a quadric' in w for w in warnings)
    ok, message = result["broken_vdb"]
    assert "broken.vdb" in output and "not a VDB file" in output
    line = [l for l in output.splitlines() if "broken.vdb" in l and "not a VDB file" in l][0]
    assert line.count("\n") == 0
    ok, message, passes = result["cancelled"]
    assert "render cancelled at 4 of 64 samples per pixel" in output
    # What the render result holds when cancelled: the passes done, 4 spp, nimbus's own pixels.
    cancelled = nimbus.read_exr(str(tmp_path / "cancelled.exr"))
    cli = cli_render(tmp_path / "cancelled.json", tmp_path / "cli4.exr", "--spp", "4")
    assert np.array_equal(cancelled, cli)
    for key, line in [("panoramic_export", 'camera "Camera": panoramic cameras are not supported'),
                      ("no_camera", "the scene has no camera"),
                      ("missing_folder", "does not exist")]:
        ok, message = result[key]
        assert not ok and line in message and message.count("\n") <= 1, (key, message)
    # Nothing is written where an export failed.
    assert result["written"] == ["before_camera.json", "cancelled.json"]
    assert result["blender_went_on"]


def test_executable_back_end_gives_the_modules_pixels(tmp_path):
    blender("executable", tmp_path)
    module = nimbus.read_exr(str(tmp_path / "module.exr"))
    executable = nimbus.read_exr(str(tmp_path / "executable.exr"))
    assert np.array_equal(module, executable)
    assert np.array_equal(module, cli_render(tmp_path / "scene.json", tmp_path / "cli.exr"))


def test_the_repositorys_blender_scene_exports_cleanly(tmp_path):
    blend = os.path.join(SOURCE, "scenes", "blender", "sculpture.blend")
    result, _ = blender("sculpture", tmp_path, blend)
    assert result["warnings"] == []
    assert result["engine"] == "NIMBUS"
    scene = nimbus.load_file(str(tmp_path / "sculpture.json"))
    assert (scene.width, scene.height) == (480, 270)
    document = json.loads((tmp_path / "sculpture.json").read_text())
    assert [o["surface"]["type"] for o in document["objects"]] == ["none", "diffuse", "dielectric"]
    assert document["media"]["Cloud"]["density"]["file"] == os.path.join(
        SOURCE, "scenes", "vdb", "vdb_cloud.vdb")
