"""Python under concurrency and hostile paths (issue 44): a film takes one render at a time, one
scene rendered from several threads gives the sequential bits, every path argument refuses a NUL
byte, and outputs follow `nimbus render -o`'s rules: atomic, never a file a loaded scene reads,
regular files only, never under /dev.

Run by ctest (test Python) with PYTHONPATH on the build's python/ folder and NIMBUS_SOURCE_DIR
the checkout. The threads meet at events, never at sleeps; the waits' limits only stop a broken
build from hanging the suite."""
import json
import os
import re
import shutil
import threading
import warnings

import numpy as np
import pytest

import nimbus

SOURCE = os.environ.get("NIMBUS_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))
DEMO = os.path.join(SOURCE, "scenes", "demo.json")
SMALL = {"film.width": 24, "film.height": 16}
GUARD = 60  # seconds: a hang, not a timing


def test_a_film_takes_one_render_at_a_time(tmp_path):
    scene = nimbus.load_file(DEMO, SMALL)
    film = nimbus.Film(scene)
    inside, refused = threading.Event(), threading.Event()
    errors = []

    def hold(done, total):  # the first render's progress: it holds the film until told
        inside.set()
        refused.wait(GUARD)

    def first():
        try:
            nimbus.render_into(scene, film, samples=(0, 16), progress=hold)
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    thread = threading.Thread(target=first)
    thread.start()
    assert inside.wait(GUARD)
    try:
        # Both returned, and the last replaced the film: 12 of its 16 samples were lost.
        with pytest.raises(ValueError, match=r"^the film is already being rendered into \(on "
                                             r"another thread\): wait for that to end"):
            nimbus.render_into(scene, film, samples=(0, 4))
        # Saved without the GIL, the film would be replaced under the writer.
        with pytest.raises(ValueError, match="already being rendered into"):
            film.save(tmp_path / "busy.film")
    finally:
        refused.set()
        thread.join()
    assert not errors
    assert film.spp == 16
    assert np.array_equal(film.image(), nimbus.render(scene, spp=16))
    assert not (tmp_path / "busy.film").exists()
    nimbus.render_into(scene, film, samples=(16, 17))  # free again
    assert film.spp == 17


EMPTY_AND_SPHERE = {
    "camera": {"from": [0, 0, 5], "to": [0, 0, 0]}, "film": {"width": 16, "height": 12},
    "lights": [{"type": "environment", "radiance": 1}],
    "shapes": {"a": {"type": "sphere", "radius": 1},
               "b": {"type": "sphere", "center": [5, 0, 0], "radius": 1},
               "e": {"type": "intersection", "shapes": ["a", "b"]}},
    "objects": [{"shape": "a"}, {"shape": "e"}]}


def test_one_scene_rendered_from_threads_gives_the_sequential_bits():
    scene = nimbus.load_dict(EMPTY_AND_SPHERE)  # not compiled yet: the threads meet at it
    count = 4
    start = threading.Barrier(count, timeout=GUARD)
    images, errors = [None] * count, []

    def work(i):
        try:
            start.wait()
            film = nimbus.Film(scene)
            nimbus.render_into(scene, film, samples=(0, 2), threads=1)
            images[i] = film.image()
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        threads = [threading.Thread(target=work, args=(i,)) for i in range(count)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    assert not errors
    # One compile for all of them: its warning once, as for one thread.
    assert [str(w.message) for w in seen] == [
        '<dict>: /objects/1/shape: shape "e" is empty (its function is positive nowhere); the '
        'object is not rendered']
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sequential = nimbus.render(scene, spp=2)
    for image in images:
        assert np.array_equal(image, sequential)


def test_every_path_argument_refuses_an_embedded_null_byte(tmp_path):
    scene_file = tmp_path / "scene.json"
    shutil.copy(DEMO, scene_file)
    scene = nimbus.load_file(scene_file, SMALL)
    film = nimbus.Film(scene)
    image = np.zeros((2, 2, 3), np.float32)
    cut = str(tmp_path / "out.exr")
    calls = [lambda: nimbus.load_file(str(scene_file) + "\0junk"),
             lambda: nimbus.load_file(os.fsencode(scene_file) + b"\0junk"),
             lambda: nimbus.write_image(cut + "\0junk", image),
             lambda: film.save(str(tmp_path / "out.film") + "\0.junk"),
             lambda: nimbus.Film.load(str(tmp_path / "out.film") + "\0junk"),
             lambda: nimbus.read_exr(cut + "\0junk")]
    for call in calls:
        with pytest.raises(ValueError, match="^embedded null byte$"):
            call()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.json"]


def test_outputs_never_replace_a_file_a_loaded_scene_reads(tmp_path):
    # A scene file, an instances file and a grid, under names an output could have.
    scene_file = tmp_path / "scene.png"
    rocks = tmp_path / "rocks.exr"
    with open(rocks, "wb") as f:
        np.save(f, np.array([[0.0, 0, 0], [2, 0, 0]]))
    shutil.copy(os.path.join(SOURCE, "scenes", "vdb", "vdb_fire.vdb"), tmp_path / "fire.film")
    scene_file.write_text(json.dumps({
        "camera": {"from": [0, 0, 8], "to": [0, 0, 0]}, "film": {"width": 8, "height": 6},
        "media": {"m": {"sigma_a": 1, "density": {"type": "vdb", "file": "fire.film"}}},
        "objects": [{"shape": {"type": "sphere", "radius": 0.5},
                     "instances": {"file": "rocks.exr"}},
                    {"shape": {"type": "sphere", "center": [0, 2, 0], "radius": 1},
                     "medium": "m"}]}))
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    scene = nimbus.load_file(scene_file)
    film = nimbus.Film(scene)  # compiled: the grid is read
    image = film.image()
    name = re.escape(str(scene_file))
    with pytest.raises(ValueError, match=rf"^write_image {name}: is the scene file \({name}\), "
                                         r"which a loaded scene reads$"):
        nimbus.write_image(scene_file, image)
    with pytest.raises(ValueError, match=r"is the file of /objects/0/instances/file"):
        nimbus.write_image(rocks, image)
    with pytest.raises(ValueError, match=r"^Film.save .*fire.film: is the file of "
                                         r"/media/m/density/file"):
        film.save(tmp_path / "fire.film")
    os.link(scene_file, tmp_path / "also.png")  # the same file under another name
    with pytest.raises(ValueError, match="is the scene file"):
        nimbus.write_image(tmp_path / "also.png", image)
    del scene, film  # the scene's files stay protected: they are often rendered again
    with pytest.raises(ValueError, match="is the scene file"):
        nimbus.write_image(scene_file, image)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.name != "also.png"} == before


def test_outputs_follow_the_command_lines_rules(tmp_path):
    image = np.zeros((2, 2, 3), np.float32)
    film = nimbus.Film(nimbus.load_file(DEMO, {"film.width": 2, "film.height": 2}))
    fifo = tmp_path / "fifo.exr"
    os.mkfifo(fifo)
    (tmp_path / "folder.exr").mkdir()
    refused = {
        tmp_path / "fifo.exr": "exists and is not a regular file",
        tmp_path / "folder.exr": "is a directory",
        tmp_path / "missing" / "a.exr": "directory .*/missing does not exist",
    }
    if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK):
        refused["/dev/shm/nimbus-test.exr"] = r"refusing to write into /dev \(a folder of devices"
    for path, problem in refused.items():
        line = f"^{re.escape(str(path))}: {problem}"
        with pytest.raises(ValueError, match=line):
            nimbus.write_image(path, image)
        with pytest.raises(ValueError, match=line):
            film.save(path)
    assert not os.path.exists("/dev/shm/nimbus-test.exr")
    with pytest.raises(ValueError, match="unknown image format"):
        nimbus.write_image(tmp_path / "a.tiff", image)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo.exr", "folder.exr"]
    # Written: atomically, no temporary file left beside it.
    film.save(tmp_path / "a.film")
    nimbus.write_image(tmp_path / "a.exr", image)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.exr", "a.film", "fifo.exr",
                                                          "folder.exr"]


def test_files_that_cannot_be_read_are_os_errors(tmp_path):
    with pytest.raises(OSError, match="missing.film"):
        nimbus.Film.load(tmp_path / "missing.film")
    with pytest.raises(OSError, match="missing.exr"):
        nimbus.read_exr(tmp_path / "missing.exr")
    (tmp_path / "short.film").write_bytes(b"NIMBUSFILM")
    with pytest.raises(OSError, match="short.film"):
        nimbus.Film.load(tmp_path / "short.film")
