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
from ._core import JobError, Scene, SceneError, __version__

__all__ = ["Scene", "SceneError", "JobError", "load_file", "load_dict", "render", "read_exr",
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
    if progress is True:
        callback = _bar
    elif progress is False or progress is None:
        callback = None
    elif callable(progress):
        total = scene.width * scene.height * (spp or scene.spp)
        callback = lambda f: progress(round(f * total), total)  # noqa: E731
    else:
        raise TypeError("progress must be False, True or a callable (done, total)")
    image, stats_json = _core.render(scene, spp or 0, seed, threads or 0, callback)
    return (image, _json.loads(stats_json)) if stats else image


def read_exr(path):
    """The R, G, B channels of an EXR file as a float32 array (height, width, 3)."""
    return _core.read_exr(_os.fspath(path))
