"""nimbus: functionally specified objects and participating media, rendered by spectral tracking.

    import nimbus
    scene = nimbus.load_file("scenes/demo.json", {"film.width": 160, "film.height": 120})
    image = nimbus.render(scene, spp=16)   # numpy float32, (height, width, 3), linear sRGB

The image holds exactly the pixels of the EXR that `nimbus render` writes for the same scene,
seed and spp, whatever the number of threads. docs/python.md walks through the API.
"""
import json as _json
import os as _os
import sys as _sys
import time as _time

from . import _core
from ._core import Film, JobError, Scene, SceneError, __version__

__all__ = ["Scene", "SceneError", "JobError", "Film", "Shape", "load_file", "load_dict", "render",
           "render_into", "write_image", "read_exr", "experiment", "experiment_names",
           "__version__"]


def _overrides(overrides):
    """{"integrator.spp": 16} as the command line's --set KEY=VALUE, values as JSON."""
    if overrides is None:
        return []
    if not isinstance(overrides, dict):
        raise TypeError(f"overrides must be a dict like {{'integrator.spp': 16}}, not "
                        f"{type(overrides).__name__}")
    out = []
    for key, value in overrides.items():
        if not isinstance(key, str):
            raise TypeError(f"an override's key must be a dotted string, not {key!r}")
        try:
            out.append(f"{key}={_json.dumps(value, allow_nan=False)}")
        except (TypeError, ValueError) as e:
            raise ValueError(f"override {key}: {e}") from None
    return out


def load_file(path, overrides=None):
    """Loads and checks a scene file (docs/scene-format.md); `overrides` as --set.

    Raises SceneError (a ValueError) with the command line's one line: FILE: /json/pointer: problem.
    """
    return _core.load_file(_os.fspath(path), _overrides(overrides))


def load_dict(document, source="<dict>"):
    """Loads and checks a scene given as a dict in the scene-file schema, exactly as a file."""
    if not isinstance(document, dict):
        raise TypeError(f"a scene document is a dict, not {type(document).__name__}")
    try:
        text = _json.dumps(document, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise SceneError(f"{source}: not a JSON document ({e})") from None
    return _core.load_text(text, source)


def _count(name, value, least, most=None):
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"{name} must be an integer, not {type(value).__name__}")
    if value < least or (most is not None and value > most):
        bound = f">= {least}" if most is None else f"in [{least}, {most}]"
        raise ValueError(f"{name} must be {bound}, not {value}")
    return value


def _bar(fraction, start=[None]):  # noqa: B006 (the bar's start time, kept between calls)
    if start[0] is None or fraction == 0:
        start[0] = _time.monotonic()
    width = 40
    filled = int(fraction * width)
    _sys.stderr.write(f"\rrender   [{'#' * filled}{'.' * (width - filled)}] {100 * fraction:5.1f}%"
                      f"  {_time.monotonic() - start[0]:6.1f}s")
    if fraction >= 1:
        _sys.stderr.write("\n")
        start[0] = None
    _sys.stderr.flush()


def render(scene, spp=None, seed=None, threads=None, progress=False, stats=False):
    """Renders a scene; returns a float32 array (height, width, 3) of linear sRGB.

    spp and seed override the scene's (integrator.spp, integrator.seed); threads: all cores when
    None (the pixels do not depend on it). progress: False, True (a bar on stderr) or a callable
    (done, total) in samples. stats=True returns (image, dict), the dict being what --stats
    writes. The GIL is released while rendering; Ctrl-C raises KeyboardInterrupt within a second.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a nimbus.Scene (load_file, load_dict), not "
                        f"{type(scene).__name__}")
    spp = _count("spp", spp, 1, 2**31 - 1)
    seed = _count("seed", seed, 0, 2**64 - 1)
    threads = _count("threads", threads, 1, 4096)
    callback = _progress(progress, scene.width * scene.height * (spp or scene.spp))
    image, stats_json = _core.render(scene, spp or 0, seed, threads or 0, callback)
    return (image, _json.loads(stats_json)) if stats else image


def _progress(progress, total):
    """The C++ side's callback (the fraction done) for render's or render_into's progress."""
    if progress is True:
        return _bar
    if progress is False or progress is None:
        return None
    if callable(progress):
        return lambda f: progress(round(f * total), total)
    raise TypeError("progress must be False, True or a callable (done, total)")


def render_into(scene, film, samples, seed=None, threads=None, progress=False, pixels=None):
    """Adds the samples [s0, s1) of every pixel to `film` (nimbus.Film(scene)).

    Consecutive ranges, (0, 8) then (8, 16), give the bits of one render of 16 samples with
    the same seed. A stopped render (Ctrl-C: KeyboardInterrupt) leaves the film as it was. A film
    takes one render_into at a time: another thread's render_into or save of it meanwhile raises
    ValueError ("the film is already being rendered into ...").

    pixels=(x0, y0, x1, y1) renders only the pixels x0 <= x < x1, y0 <= y < y1 (the others keep
    what they hold); each pixel's samples are those of the whole image's render, so regions that
    tile the image give its bits. With a noise target a region covers whole 8x8 blocks.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a nimbus.Scene, not {type(scene).__name__}")
    if not isinstance(film, Film):
        raise TypeError(f"film must be a nimbus.Film, not {type(film).__name__}")
    try:
        s0, s1 = samples
    except (TypeError, ValueError):
        raise TypeError("samples must be a pair (s0, s1) of sample indices") from None
    s0 = _count("samples[0]", s0, 0, 2**31 - 2)
    s1 = _count("samples[1]", s1, 1, 2**31 - 1)
    if s1 <= s0:
        raise ValueError(f"samples must be a range s0 < s1, not ({s0}, {s1})")
    seed = _count("seed", seed, 0, 2**64 - 1)
    threads = _count("threads", threads, 1, 4096)
    if pixels is None:
        region = (0, 0, -1, -1)  # the whole image
    else:
        try:
            x0, y0, x1, y1 = pixels
        except (TypeError, ValueError):
            raise TypeError("pixels must be a tuple (x0, y0, x1, y1) of pixel indices") from None
        region = (_count("pixels[0]", x0, 0, film.width), _count("pixels[1]", y0, 0, film.height),
                  _count("pixels[2]", x1, 0, film.width), _count("pixels[3]", y1, 0, film.height))
        if x1 <= x0 or y1 <= y0:
            raise ValueError(f"pixels must be a region x0 < x1, y0 < y1, not {tuple(pixels)}")
    count = (film.width * film.height if pixels is None
             else (region[2] - region[0]) * (region[3] - region[1]))
    callback = _progress(progress, count * (s1 - s0))
    _core.render_into(scene, film, s0, s1, region, seed, threads or 0, callback)


def write_image(path, array):
    """Writes a (height, width, 3) array of linear sRGB as EXR (float) or PNG (sRGB, 8 bits),
    by the file's extension, atomically (a temporary file, then a rename), as nimbus render.

    The path follows `nimbus render -o`'s rules: ValueError, before writing, for an unknown
    extension, a missing or unwritable folder, /dev, /proc or /sys, a directory, FIFO or device,
    or a file that a scene loaded in this process reads (docs/python.md, "Paths and files").
    OSError if the file cannot be written."""
    import numpy as np
    a = np.asarray(array)
    if a.dtype.kind not in "fiu":
        raise TypeError(f"an image is an array of numbers, not of {a.dtype}")
    if a.ndim != 3 or a.shape[2] != 3 or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"an image is an array of shape (height, width, 3), not {a.shape}")
    _core.write_image(_os.fspath(path), np.ascontiguousarray(a, dtype=np.float32))


class Shape:
    """A shape of the scene format (docs/scene-format.md, "Shapes"), compiled as nimbus renders it.

        blob = nimbus.Shape({"type": "freeform", "base": {"type": "sphere", "radius": 1},
                             "perturbations": [{"shape": "bump", "weight": 2}]},
                            shapes={"bump": {"type": "sphere", "center": [1, 0, 0], "radius": 0.5}})
        f = blob.values(points)                  # F at an (n, 3) array: (n,), > 0 inside
        t = blob.first_hit(origins, directions)  # (n,), inf where a ray misses

    `shape` is a shape value (a dict) or the name of one in `shapes`, a dict of named shapes as
    the scene file's table. Errors are SceneError lines: "<shape>: /shape/radius: must be in [1e-100, 1e+100]".
    F is the function as written: quadrics keep their coefficients' scale (no normalisation).
    The vectorised calls release the GIL and run on all cores.
    """

    def __init__(self, shape, shapes=None, source="<shape>"):
        if not isinstance(shape, (dict, str)):
            raise TypeError(f"a shape is a dict (or a name in shapes), not {type(shape).__name__}")
        if shapes is not None and not isinstance(shapes, dict):
            raise TypeError(f"shapes must be a dict of named shapes, not {type(shapes).__name__}")
        try:
            text = _json.dumps(shape, allow_nan=False)
            table = "" if shapes is None else _json.dumps(shapes, allow_nan=False)
        except (TypeError, ValueError) as e:
            raise SceneError(f"{source}: not a JSON document ({e})") from None
        self._shape = _core.Shape(text, table, source)

    def values(self, points):
        """F at each row of an (n, 3) array of points (float64): an (n,) array, > 0 inside."""
        return self._shape.values(points)

    def first_hit(self, origins, directions, t_max=float("inf")):
        """The first t in [0, t_max] where each ray o + t d crosses the surface: (n,), inf where
        it does not. origins and directions are (n, 3) arrays; directions need not be unit."""
        return self._shape.first_hit(origins, directions, float(t_max))

    def bounds(self):
        """(lo, hi), each a float64 array of 3, around {F > 0}; +-inf where unbounded; None when
        the shape is empty."""
        return self._shape.bounds()

    def mesh(self, error):
        """The surface as a closed triangle mesh to the error bound `error` (scene units, > 0):
        (vertices, faces, normals), arrays of shape (n, 3) float64, (m, 3) uint32 (counter-
        clockwise seen from outside) and (n, 3) float64 (the exact gradient's, outward). Every
        vertex lies within `error` of the surface (docs/meshes.md). Releases the GIL. ValueError
        for a bound <= 0, an empty or unbounded shape, or a bound whose grid would need more
        memory than is available (the message gives the estimate)."""
        return self._shape.mesh(float(error))


def experiment_names():
    """The paper-reproduction experiments (docs/reproduction.md), in the order of its figures."""
    return list(_core.experiment_names())


def _scenes_dir():
    """scenes/ of an installed prefix (PREFIX/share/nimbus beside lib/python3/dist-packages),
    else the build tree's."""
    here = _os.path.dirname(_os.path.abspath(__file__))
    installed = _os.path.join(here, "..", "..", "..", "..", "share", "nimbus", "scenes")
    return installed if _os.path.isdir(installed) else _core._build_scenes_dir


def _read_csv(path):
    """A CSV file's columns as arrays: numbers as float64, anything else as str."""
    import csv
    import numpy as np
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    columns = {}
    for k, name in enumerate(rows[0]):
        cells = [r[k] if k < len(r) else "" for r in rows[1:]]
        try:
            columns[name] = np.array([float(c) for c in cells])
        except ValueError:
            columns[name] = np.array(cells)
    return columns


def experiment(name, quick=False, seed=0, threads=None):
    """Runs `nimbus experiment NAME` and returns what it writes as CSV as arrays:
    {"summary": str, CSV_STEM: {column: array}, ...}. The GIL is released while it runs."""
    import tempfile
    if not isinstance(name, str):
        raise TypeError(f"an experiment's name is a str, not {type(name).__name__}")
    seed = _count("seed", seed, 0, 2**64 - 1)
    threads = _count("threads", threads, 1, 4096)
    with tempfile.TemporaryDirectory(prefix="nimbus-experiment-") as out:
        files, summary = _core.run_experiment(name, out, _scenes_dir(), bool(quick), seed,
                                              threads or 0)
        result = {"summary": summary}
        for path in files:
            if path.endswith(".csv"):
                result[_os.path.splitext(_os.path.basename(path))[0]] = _read_csv(path)
    return result


def read_exr(path, layer=None):
    """The R, G, B channels of an EXR file as a float32 array (height, width, 3); with `layer`,
    that layer's channels instead (height, width, channels): "albedo" (R, G, B), "normal"
    (X, Y, Z), "depth" (Z) or "variance" (R, G, B) of a render with AOVs, or any layer NAME of
    channels NAME.C. ValueError names the file's layers when it has no such layer."""
    if layer is not None and not isinstance(layer, str):
        raise TypeError(f"layer must be a str, not {type(layer).__name__}")
    return _core.read_exr(_os.fspath(path), layer or "")
