"""The Python module against the command line (issue 27): the same pixels, the same errors,
bad arguments refused, the GIL released while rendering, Ctrl-C ending a render.

Run by ctest (test Python) with PYTHONPATH on the build's python/ folder, NIMBUS_EXE the nimbus
executable and NIMBUS_SOURCE_DIR the checkout."""
import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import nimbus

SOURCE = os.environ.get("NIMBUS_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("NIMBUS_EXE", os.path.join(SOURCE, "build", "nimbus"))
DEMO = os.path.join(SOURCE, "scenes", "demo.json")
SMALL = {"film.width": 24, "film.height": 16}


def cli_render(tmp_path, scene, *args):
    out = tmp_path / "cli.exr"
    subprocess.run([EXE, "render", str(scene), "-o", str(out), "-q", *args], check=True)
    return nimbus.read_exr(out)


def test_the_pixels_are_the_command_lines_to_the_bit(tmp_path):
    reference = cli_render(tmp_path, DEMO, "--spp", "4", "--seed", "7",
                           "--set", "film.width=24", "--set", "film.height=16")
    image = nimbus.render(nimbus.load_file(DEMO, SMALL), spp=4, seed=7)
    assert image.dtype == np.float32
    assert image.shape == (16, 24, 3)
    assert np.array_equal(image, reference)
    assert image.mean() > 0


def test_a_dict_renders_as_its_file(tmp_path):
    with open(DEMO) as f:
        document = json.load(f)
    document["film"] = {**document.get("film", {}), "width": 24, "height": 16}
    image = nimbus.render(nimbus.load_dict(document), spp=2)
    assert np.array_equal(image, nimbus.render(nimbus.load_file(DEMO, SMALL), spp=2))


def test_the_thread_count_changes_no_pixel():
    scene = nimbus.load_file(DEMO, SMALL)
    assert np.array_equal(nimbus.render(scene, spp=3, threads=1),
                          nimbus.render(scene, spp=3, threads=2))


def test_errors_are_the_command_lines_line(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"camera": {"from": [0, 0, 5], "to": [0, 0, 0]}, '
                   '"objects": [{"shape": "blobb"}]}')
    cli = subprocess.run([EXE, "render", str(bad), "-o", str(tmp_path / "x.exr")],
                         capture_output=True, text=True)
    assert cli.returncode == 2
    with pytest.raises(nimbus.SceneError) as e:
        nimbus.load_file(bad)
    assert str(e.value) == cli.stderr.strip()
    assert "/objects/0/shape" in str(e.value)
    assert isinstance(e.value, ValueError)
    with pytest.raises(nimbus.SceneError, match=r'^<dict>: /objects/0/shape: unknown shape "blobb"'):
        nimbus.load_dict(json.loads(bad.read_text()))
    with pytest.raises(nimbus.SceneError, match=r"/integrator/spp: expected an integer"):
        nimbus.load_file(DEMO, {"integrator.spp": "many"})
    with pytest.raises(nimbus.SceneError, match="cannot open file"):
        nimbus.load_file(tmp_path / "missing.json")
    with pytest.raises(nimbus.SceneError, match="not a JSON document"):
        nimbus.load_dict({"camera": float("nan")})


def test_an_empty_shape_is_a_warning_from_both(tmp_path):
    document = {"camera": {"from": [0, 0, 5], "to": [0, 0, 0]}, "film": {"width": 8, "height": 8},
                "shapes": {"a": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
                           "b": {"type": "sphere", "center": [5, 0, 0], "radius": 1},
                           "e": {"type": "intersection", "shapes": ["a", "b"]}},
                "objects": [{"shape": "a"}, {"shape": "e"}]}
    scene = tmp_path / "empty.json"
    scene.write_text(json.dumps(document))
    cli = subprocess.run([EXE, "render", str(scene), "-o", str(tmp_path / "x.exr"), "-q",
                          "--spp", "1"], capture_output=True, text=True)
    assert cli.returncode == 0
    line = (f'nimbus: warning: {scene}: /objects/1/shape: shape "e" is empty (its function is '
            'positive nowhere); the object is not rendered')
    assert cli.stderr.splitlines() == [line]
    with pytest.warns(UserWarning, match=r'^<dict>: /objects/1/shape: shape "e" is empty'):
        nimbus.render(nimbus.load_dict(document), spp=1)


def test_bad_arguments_raise_value_or_type_errors():
    scene = nimbus.load_file(DEMO, SMALL)
    for spp in (0, -1):
        with pytest.raises(ValueError, match="spp must be"):
            nimbus.render(scene, spp=spp)
    for spp in (1.5, "4", True):
        with pytest.raises(TypeError, match="spp must be an integer"):
            nimbus.render(scene, spp=spp)
    with pytest.raises(ValueError, match="threads must be"):
        nimbus.render(scene, spp=1, threads=0)
    with pytest.raises(ValueError, match="seed must be"):
        nimbus.render(scene, spp=1, seed=-3)
    with pytest.raises(TypeError, match="nimbus.Scene"):
        nimbus.render(DEMO)
    with pytest.raises(TypeError, match="overrides must be a dict"):
        nimbus.load_file(DEMO, ["film.width=3"])
    with pytest.raises(TypeError, match="progress must be"):
        nimbus.render(scene, spp=1, progress="yes")
    with pytest.raises(TypeError, match="a scene document is a dict"):
        nimbus.load_dict("scene.json")


def test_stats_and_progress():
    scene = nimbus.load_file(DEMO, SMALL)
    seen = []
    image, stats = nimbus.render(scene, spp=2, stats=True, progress=lambda d, t: seen.append((d, t)))
    assert image.shape == (16, 24, 3)
    assert stats["samples_per_second"] > 0
    assert seen and seen[-1] == (24 * 16 * 2, 24 * 16 * 2)
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))
    assert nimbus.__version__


def test_other_threads_run_while_rendering():
    scene = nimbus.load_file(DEMO, {"film.width": 96, "film.height": 64})
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.005)

    t = threading.Thread(target=tick)
    t.start()
    start = time.monotonic()
    nimbus.render(scene, spp=64, threads=1)
    end = time.monotonic()
    stop.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    # The render holds the GIL only between its 50 ms polls: the ticker runs throughout (ten
    # ticks at the least, however loaded the machine; none if the render held the GIL).
    assert end - start > 0.2
    assert len(during) >= 10


def test_ctrl_c_ends_a_render_with_keyboard_interrupt():
    script = ("import sys, nimbus\n"
              f"s = nimbus.load_file({DEMO!r}, {{'film.width': 256, 'film.height': 256}})\n"
              "print('ready', flush=True)\n"
              "nimbus.render(s, spp=100000)\n")
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=os.environ.copy())
    assert child.stdout.readline().strip() == "ready"
    time.sleep(0.5)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=30)
    # Promptly: the render would take minutes (a loaded machine may take seconds to schedule it).
    assert time.monotonic() - sent < 20
    assert child.returncode != 0
    assert "KeyboardInterrupt" in err


def test_the_example_script_makes_its_figure(tmp_path):
    out = tmp_path / "figure.png"
    # A quarter of the example's pixels and reference samples: the same code, a ninth of the time.
    run = subprocess.run([sys.executable, os.path.join(SOURCE, "examples", "python", "spp_figure.py"),
                          str(out), "--size", "48", "36", "--reference-spp", "64"],
                         capture_output=True, text=True, env=os.environ.copy())
    assert run.returncode == 0, run.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_two_sample_ranges_give_one_renders_bits(tmp_path):
    scene = nimbus.load_file(DEMO, SMALL)
    film = nimbus.Film(scene)
    assert (film.width, film.height, film.spp) == (24, 16, 0)
    nimbus.render_into(scene, film, samples=(0, 3), seed=5)
    assert film.spp == 3
    nimbus.render_into(scene, film, samples=(3, 6), seed=5, threads=1)
    assert film.spp == 6
    whole = nimbus.render(scene, spp=6, seed=5)
    assert np.array_equal(film.image(), whole)
    variance = film.variance()
    assert variance.shape == (16, 24, 3) and variance.dtype == np.float32
    assert (variance >= 0).all() and variance.max() > 0
    film.save(tmp_path / "demo.film")
    again = nimbus.Film.load(tmp_path / "demo.film")
    assert np.array_equal(again.image(), whole) and again.spp == 6


def test_regions_of_pixels_tile_one_renders_bits():
    # pixels=(x0, y0, x1, y1): each pixel's samples are the whole render's, so regions that tile
    # the image give its bits, and the pixels outside a region keep what they hold.
    scene = nimbus.load_file(DEMO, SMALL)
    whole = nimbus.render(scene, spp=4, seed=2)
    film = nimbus.Film(scene)
    nimbus.render_into(scene, film, samples=(0, 4), seed=2, pixels=(0, 0, 24, 5))
    counts = film.samples()
    assert (counts[:5] == 4).all() and (counts[5:] == 0).all() and film.spp == 0
    assert np.array_equal(film.image()[:5], whole[:5]) and not film.image()[5:].any()
    nimbus.render_into(scene, film, samples=(0, 4), seed=2, pixels=(0, 5, 7, 16))
    nimbus.render_into(scene, film, samples=(0, 4), seed=2, pixels=(7, 5, 24, 16), threads=1)
    assert film.spp == 4 and np.array_equal(film.image(), whole)
    # With a noise target a region covers whole blocks, and its blocks decide as in the image.
    target = nimbus.load_file(DEMO, {**SMALL, "integrator.noise_target": 0.05,
                                     "integrator.spp": 128})
    image = nimbus.render(target, spp=128, seed=3)
    film = nimbus.Film(target)
    nimbus.render_into(target, film, samples=(0, 128), seed=3, pixels=(0, 0, 8, 16))
    nimbus.render_into(target, film, samples=(0, 128), seed=3, pixels=(8, 0, 24, 16))
    assert np.array_equal(film.image(), image)
    with pytest.raises(ValueError, match="must cover whole 8x8 blocks"):
        nimbus.render_into(target, nimbus.Film(target), samples=(0, 16), pixels=(4, 0, 24, 16))


def test_regions_of_pixels_are_checked():
    scene = nimbus.load_file(DEMO, SMALL)
    film = nimbus.Film(scene)
    for pixels in [(0, 0, 25, 16), (-1, 0, 4, 4), (0, 0, 4, 17)]:
        with pytest.raises(ValueError, match="pixels\\[[0-3]\\] must be in"):
            nimbus.render_into(scene, film, samples=(0, 1), pixels=pixels)
    for pixels in [(4, 0, 4, 4), (0, 6, 4, 2)]:
        with pytest.raises(ValueError, match="x0 < x1, y0 < y1"):
            nimbus.render_into(scene, film, samples=(0, 1), pixels=pixels)
    for pixels in [(0, 0, 4), "abcd", 3, (0, 0, 4.0, 4)]:
        with pytest.raises(TypeError):
            nimbus.render_into(scene, film, samples=(0, 1), pixels=pixels)
    nimbus.render_into(scene, film, samples=(0, 2), pixels=(0, 0, 4, 4))
    with pytest.raises(ValueError, match="pixel \\(0, 0\\) holds 2 samples"):
        nimbus.render_into(scene, film, samples=(0, 1), pixels=(0, 0, 8, 8))
    assert film.samples()[:4, :4].min() == 2 and film.samples().sum() == 32


def test_a_noise_target_renders_as_the_command_line_and_in_ranges(tmp_path):
    # Blocks of 8x8 pixels stop where their error meets the target (docs/noise-target.md): the
    # same pixels from render, from render_into in two ranges, and from nimbus render.
    target = {**SMALL, "integrator.noise_target": 0.05}
    scene = nimbus.load_file(DEMO, target)
    image, stats = nimbus.render(scene, spp=256, seed=3, stats=True)
    assert stats["noise_target"]["pixels_done"] == 1.0
    reference = cli_render(tmp_path, DEMO, "--spp", "256", "--seed", "3", "--noise-target",
                           "0.05", "--set", "film.width=24", "--set", "film.height=16")
    assert np.array_equal(image, reference)
    capped = nimbus.load_file(DEMO, {**target, "integrator.spp": 256})
    film = nimbus.Film(capped)
    nimbus.render_into(capped, film, samples=(0, 50), seed=3)
    nimbus.render_into(capped, film, samples=(50, 256), seed=3)
    assert np.array_equal(film.image(), image)
    counts = film.samples()
    assert counts.shape == (16, 24) and counts.dtype == np.uint32
    assert counts.min() >= 16 and counts.max() > counts.min()
    assert film.spp == counts.min()
    with pytest.raises(ValueError, match="go past the spp, 256"):
        nimbus.render_into(capped, nimbus.Film(capped), samples=(0, 300))


def test_films_and_ranges_are_checked():
    scene = nimbus.load_file(DEMO, SMALL)
    other = nimbus.load_file(DEMO, {"film.width": 8, "film.height": 8})
    film = nimbus.Film(other)
    with pytest.raises(ValueError, match="the film is 8x8, the scene's image 24x16"):
        nimbus.render_into(scene, film, samples=(0, 1))
    for samples in [(3, 3), (4, 2)]:
        with pytest.raises(ValueError, match="s0 < s1"):
            nimbus.render_into(other, film, samples=samples)
    with pytest.raises(ValueError, match="samples\\[0\\] must be"):
        nimbus.render_into(other, film, samples=(-1, 2))
    for samples in ["ab", 3, (1.0, 2)]:
        with pytest.raises(TypeError):
            nimbus.render_into(other, film, samples=samples)
    with pytest.raises(TypeError, match="film must be a nimbus.Film"):
        nimbus.render_into(other, np.zeros((8, 8, 3)), samples=(0, 1))
    assert film.spp == 0  # nothing was rendered into it


def test_write_image_writes_exr_and_png_atomically(tmp_path):
    image = nimbus.render(nimbus.load_file(DEMO, SMALL), spp=2)
    nimbus.write_image(tmp_path / "a.exr", image)
    assert np.array_equal(nimbus.read_exr(tmp_path / "a.exr"), image)
    nimbus.write_image(tmp_path / "a.png", image.astype(np.float64))
    assert (tmp_path / "a.png").read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(ValueError, match="shape \\(height, width, 3\\)"):
        nimbus.write_image(tmp_path / "b.exr", np.zeros((4, 4)))
    with pytest.raises(TypeError, match="array of numbers"):
        nimbus.write_image(tmp_path / "b.exr", np.array([[["a"] * 3]]))
    with pytest.raises(Exception, match="b.tiff"):
        nimbus.write_image(tmp_path / "b.tiff", image)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.exr", "a.png"]


def test_a_stopped_render_into_leaves_the_film_as_it_was():
    scene = nimbus.load_file(DEMO, {"film.width": 128, "film.height": 128})
    film = nimbus.Film(scene)
    nimbus.render_into(scene, film, samples=(0, 1))
    before = film.image()

    def stop(done, total):
        if done < total:
            raise RuntimeError("stopped by the callback")

    with pytest.raises(RuntimeError, match="stopped by the callback"):
        nimbus.render_into(scene, film, samples=(1, 2000), progress=stop)
    assert film.spp == 1
    assert np.array_equal(film.image(), before)


def sphere_f(p, c, r):
    return r * r - np.sum((p - np.asarray(c)) ** 2, axis=1)


BLOB = {"type": "freeform", "base": {"type": "sphere", "radius": 1},
        "perturbations": [{"shape": "bump", "weight": 2},
                          {"shape": {"type": "sphere", "center": [-0.5, 0.6, 0.4], "radius": 0.5},
                           "weight": -3}]}
NAMED = {"bump": {"type": "sphere", "center": [0.8, 0.3, 0], "radius": 0.5}}
CARVED = {"type": "difference", "shapes": [
    {"type": "union", "shapes": [{"type": "sphere", "radius": 1},
                                 {"type": "sphere", "center": [1.2, 0, 0], "radius": 0.6}]},
    {"type": "sphere", "center": [0, 0, 1], "radius": 0.7}]}


def blob_f(p):
    bump = lambda c, r: np.maximum(sphere_f(p, c, r), 0) ** 3  # noqa: E731
    return sphere_f(p, [0, 0, 0], 1) + 2 * bump([0.8, 0.3, 0], 0.5) - 3 * bump([-0.5, 0.6, 0.4], 0.5)


def carved_f(p):
    union = np.maximum(sphere_f(p, [0, 0, 0], 1), sphere_f(p, [1.2, 0, 0], 0.6))
    return np.minimum(union, -sphere_f(p, [0, 0, 1], 0.7))


def test_shape_values_are_a_numpy_evaluation_of_the_same_function():
    points = np.random.default_rng(3).uniform(-2, 2, (5000, 3))
    for shape, f in [(nimbus.Shape(BLOB, NAMED), blob_f), (nimbus.Shape(CARVED), carved_f)]:
        values = shape.values(points)
        assert values.shape == (5000,) and values.dtype == np.float64
        assert np.allclose(values, f(points), rtol=1e-12, atol=1e-12)
        assert (values > 0).any() and (values < 0).any()
    moved = nimbus.Shape({"type": "union", "shapes": ["bump"],
                          "transform": [{"translate": [1, 2, 3]}]}, NAMED)
    assert np.allclose(moved.values(points), sphere_f(points, [1.8, 2.3, 3], 0.5), atol=1e-12)


def test_shape_values_stay_numbers_at_the_ends_of_the_documented_ranges():
    # Issue 44: a perturbation of radius 1e100 with weights +1e15 and -1e15 gave NaN (its F of
    # 1e200 cubed overflows: inf - inf). Each cube saturates at 1e280 (docs/scene-format.md).
    huge = {"type": "sphere", "radius": 1e100}
    shape = nimbus.Shape({"type": "freeform", "base": {"type": "sphere", "radius": 1},
                          "perturbations": [{"shape": huge, "weight": 1e15},
                                            {"shape": huge, "weight": -1e15}]})
    points = np.array([[0, 0, 0], [0.5, 0, 0], [2, 0, 0], [1e50, 0, 0], [1e100, 0, 0],
                       [-1e100, 1e100, 1e100]], float)
    values = shape.values(points)
    assert np.isfinite(values).all(), values


def test_first_hit_is_where_dense_sampling_finds_the_first_crossing():
    rng = np.random.default_rng(7)
    origins = rng.normal(size=(300, 3))
    origins = 3 * origins / np.linalg.norm(origins, axis=1, keepdims=True)
    targets = rng.uniform(-0.8, 0.8, (300, 3))
    directions = targets - origins
    directions[::10] *= -1  # these point away: they miss
    for shape, f in [(nimbus.Shape(BLOB, NAMED), blob_f), (nimbus.Shape(CARVED), carved_f)]:
        t = shape.first_hit(origins, directions, t_max=2.0)
        steps = np.linspace(0, 2.0, 20001)
        hits = 0
        for i in range(len(origins)):
            along = f(origins[i] + steps[:, None] * directions[i])
            change = np.nonzero(np.sign(along[1:]) != np.sign(along[:-1]))[0]
            if len(change) == 0:
                assert t[i] == np.inf, i
                continue
            hits += 1
            k = change[0]
            assert steps[k] - 1e-9 <= t[i] <= steps[k + 1] + 1e-9, (i, t[i], steps[k])
        assert hits > 200


def test_shape_bounds_hold_the_inside():
    shape = nimbus.Shape(BLOB, NAMED)
    lo, hi = shape.bounds()
    points = np.random.default_rng(5).uniform(-2, 2, (20000, 3))
    inside = points[shape.values(points) > 0]
    assert len(inside) > 1000
    assert (inside >= lo).all() and (inside <= hi).all()
    assert nimbus.Shape({"type": "intersection", "shapes": [
        {"type": "sphere", "radius": 1}, {"type": "sphere", "center": [5, 0, 0], "radius": 1}]}
    ).bounds() is None
    lo, hi = nimbus.Shape({"type": "halfspace", "normal": [0, 1, 0]}).bounds()
    assert np.isinf(lo).any() and np.isinf(hi).any()


def test_shape_mesh_is_closed_outward_and_near_the_surface():
    """Shape.mesh: a ball's vertices within the bound of the sphere, its enclosed volume within
    0.5 %, every edge used twice in opposite directions, normals outward; bad bounds and shapes
    are ValueErrors."""
    ball = nimbus.Shape({"type": "sphere", "center": [0.2, 0, 0], "radius": 1})
    v, f, n = ball.mesh(error=0.002)
    assert v.dtype == np.float64 and f.dtype == np.uint32 and n.shape == v.shape
    assert np.abs(np.linalg.norm(v - [0.2, 0, 0], axis=1) - 1).max() <= 0.002
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
    assert abs(volume - 4 / 3 * np.pi) < 0.005 * 4 / 3 * np.pi
    edges = set(map(tuple, np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]).tolist()))
    assert len(edges) == 3 * len(f) and all((q, p) in edges for p, q in edges)
    assert (np.einsum("ij,ij->i", n, v - [0.2, 0, 0]) > 0.99).all()
    blob_v, _, _ = nimbus.Shape(BLOB, NAMED).mesh(0.01)
    assert np.abs(nimbus.Shape(BLOB, NAMED).values(blob_v)).max() < 0.1
    with pytest.raises(ValueError, match="must be > 0"):
        ball.mesh(0)
    with pytest.raises(ValueError, match="empty"):
        nimbus.Shape({"type": "intersection", "shapes": [
            {"type": "sphere", "radius": 1}, {"type": "sphere", "center": [5, 0, 0], "radius": 1}]}
        ).mesh(0.01)
    with pytest.raises(ValueError, match="unbounded"):
        nimbus.Shape({"type": "halfspace", "normal": [0, 1, 0]}).mesh(0.01)


def test_bad_shapes_and_arrays_are_refused():
    with pytest.raises(nimbus.SceneError, match=r"^<shape>: /shape/radius: must be in \[1e-100"):
        nimbus.Shape({"type": "sphere", "radius": -1})
    with pytest.raises(nimbus.SceneError, match=r'unknown shape "nope"'):
        nimbus.Shape("nope")
    with pytest.raises(nimbus.SceneError, match=r"^<shape>: /shapes/bump/radius"):
        nimbus.Shape("bump", {"bump": {"type": "sphere"}})
    with pytest.raises(TypeError):
        nimbus.Shape(3)
    shape = nimbus.Shape(BLOB, NAMED)
    with pytest.raises(ValueError, match=r"points must be an array of shape \(n, 3\), not \(3, 2\)"):
        shape.values(np.zeros((3, 2)))
    bad = np.zeros((3, 3))
    bad[1, 2] = np.nan
    with pytest.raises(ValueError, match=r"points\[1\] is not finite"):
        shape.values(bad)
    with pytest.raises(ValueError, match=r"directions\[0\] is zero"):
        shape.first_hit(np.ones((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="as many rows"):
        shape.first_hit(np.ones((2, 3)), np.ones((3, 3)))
    with pytest.raises(ValueError, match="t_max"):
        shape.first_hit(np.ones((2, 3)), np.ones((2, 3)), t_max=float("nan"))
    assert shape.values(np.zeros((0, 3))).shape == (0,)


def test_media_at_points_add_where_media_overlap():
    document = {
        "camera": {"from": [0, 0, 5], "to": [0, 0, 0]},
        "media": {"a": {"sigma_a": [1, 2, 3], "sigma_s": [4, 5, 6]},
                  "b": {"sigma_a": 0.5, "sigma_s": 0.25},
                  "glass": {"sigma_a": 7, "sigma_s": 8}},
        "objects": [
            {"shape": {"type": "sphere", "center": [-0.5, 0, 0], "radius": 1}, "medium": "a"},
            {"shape": {"type": "sphere", "center": [0.5, 0, 0], "radius": 1}, "medium": "b"},
            {"shape": {"type": "sphere", "center": [5, 0, 0], "radius": 1}, "medium": "glass",
             "surface": {"type": "dielectric"}}]}
    scene = nimbus.load_dict(document)
    points = np.array([[-1.2, 0, 0], [0, 0, 0], [1.2, 0, 0], [0, 3, 0], [5, 0, 0]])
    sigma_a, sigma_s = scene.media_at(points)
    assert np.allclose(sigma_a, [[1, 2, 3], [1.5, 2.5, 3.5], [0.5] * 3, [0] * 3, [7] * 3])
    assert np.allclose(sigma_s, [[4, 5, 6], [4.25, 5.25, 6.25], [0.25] * 3, [0] * 3, [8] * 3])
    with pytest.raises(ValueError, match="points must be an array"):
        scene.media_at(np.zeros(3))


def test_experiments_return_the_command_lines_csv_as_arrays(tmp_path):
    assert "throughput" in nimbus.experiment_names()
    result = nimbus.experiment("throughput", quick=True, seed=3)
    subprocess.run([EXE, "experiment", "throughput", "--quick", "--seed", "3", "--no-plot",
                    "--out", str(tmp_path)], check=True, capture_output=True)
    import csv
    with open(tmp_path / "throughput.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    columns = result["throughput"]
    assert len(columns["mean"]) == len(rows) > 0
    assert np.array_equal(columns["mean"], [float(r["mean"]) for r in rows])
    assert list(columns["channel"]) == [r["channel"] for r in rows]
    with pytest.raises(ValueError, match="unknown experiment \"nope\""):
        nimbus.experiment("nope")


def test_threads_rendering_one_scene_with_other_seeds_get_their_own_bits():
    scene = nimbus.load_file(DEMO, SMALL)
    results, errors = {}, []

    def work(seed):
        try:
            for _ in range(3):  # the scene's compiled cache changes seed under the other thread
                film = nimbus.Film(scene)
                nimbus.render_into(scene, film, samples=(0, 2), seed=seed, threads=1)
            results[seed] = film.image()
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    threads = [threading.Thread(target=work, args=(seed,)) for seed in (11, 12)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    for seed in (11, 12):
        assert np.array_equal(results[seed], nimbus.render(scene, spp=2, seed=seed))


def test_rough_metals_and_their_errors_through_a_dict():
    """Issue 42's surface keys from Python: a rough named metal renders as its file does, and a
    bad key is the loader's one line."""
    document = {
        "film": {"width": 8, "height": 8},
        "camera": {"from": [0, 0, 4], "to": [0, 0, 0], "fov": 30},
        "lights": [{"type": "environment", "radiance": 1}],
        "objects": [{"shape": {"type": "sphere", "radius": 1},
                     "surface": {"type": "conductor", "metal": "gold", "roughness": 0.3}}],
    }
    image = nimbus.render(nimbus.load_dict(document), spp=4)
    assert np.isfinite(image).all()
    centre = image[3:5, 3:5].mean(axis=(0, 1))
    assert centre[0] > centre[2]  # gold reflects more red than blue
    document["objects"][0]["surface"]["metal"] = "brass"
    with pytest.raises(nimbus.SceneError, match=r'/objects/0/surface/metal: unknown metal "brass"'):
        nimbus.load_dict(document)
    document["objects"][0]["surface"] = {"type": "dielectric", "roughness": 2}
    with pytest.raises(nimbus.SceneError, match=r"/objects/0/surface/roughness: must be in \[0, 1\]"):
        nimbus.load_dict(document)


def test_solid_textures_through_a_dict():
    """Solid textures from Python: a floor whose albedo follows bands renders brighter where the
    bands say so, media_at reports a textured sigma_a at a point, in the object's own
    coordinates, and a texture where none is taken is the loader's one line."""
    veins = {"type": "veins", "frequency": 0.25, "turbulence": 0, "direction": [1, 0, 0]}
    document = {
        "film": {"width": 16, "height": 4},
        "camera": {"type": "orthographic", "from": [0, 3, 0], "to": [0, 0, 0], "up": [0, 0, -1],
                   "width": 2},
        "lights": [{"type": "environment", "radiance": 1}],
        "media": {"m": {"sigma_a": {"texture": veins, "from": 0.5, "to": 2.5}}},
        "objects": [
            {"shape": {"type": "box", "min": [-20, -1, -20], "max": [20, 0, 20]},
             "surface": {"type": "diffuse", "albedo": {"texture": veins, "from": 0.1, "to": 0.9}}},
            {"shape": {"type": "sphere", "center": [0, -5, 0], "radius": 1}, "medium": "m"},
        ],
    }
    scene = nimbus.load_dict(document)
    image = nimbus.render(scene, spp=16)
    # t(x) = (1 + sin(π x / 2)) / 2 rises from x = -1 (0) to x = 1 (1) across the view.
    assert image[:, -2:, 0].mean() > image[:, :2, 0].mean() + 0.4
    x = np.array([0.5, -0.5])
    sigma_a, _ = scene.media_at(np.stack([x, [-5.0, -5.0], [0.0, 0.0]], axis=1))
    assert np.allclose(sigma_a[:, 0], 0.5 + 2.0 * (1 + np.sin(np.pi * x / 2)) / 2)
    # Textures are in the object's own coordinates: a moved sphere carries its texture along.
    document["objects"][1]["shape"]["transform"] = [{"translate": [0.75, 0, 0]}]
    moved, _ = nimbus.load_dict(document).media_at(np.stack([x + 0.75, [-5.0, -5.0], [0.0, 0.0]], axis=1))
    assert np.allclose(moved, sigma_a)
    document["objects"][0]["surface"] = {"type": "dielectric", "ior": {"texture": veins}}
    with pytest.raises(nimbus.SceneError, match=r"/objects/0/surface/ior: takes no texture"):
        nimbus.load_dict(document)
