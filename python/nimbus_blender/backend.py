"""How the add-on reaches nimbus: its Python module in Blender's own interpreter, or else the
`nimbus` executable (docs/blender.md, "How it renders")."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

_HERE = os.path.dirname(os.path.abspath(__file__))


class Cancelled(Exception):
    """Raised from the progress callback to stop a render: the film keeps the passes before."""


def _layout():
    """Where the build tree or the install put the module and the executable, relative to this
    folder (written by CMake beside the add-on; absent in a source checkout)."""
    try:
        with open(os.path.join(_HERE, "paths.json"), encoding="utf-8") as f:
            paths = json.load(f)
    except OSError:
        return None, None
    module = os.path.normpath(os.path.join(_HERE, paths["python"]))
    executable = os.path.normpath(os.path.join(_HERE, paths["executable"]))
    return module, executable


def load_module(folder=""):
    """The nimbus module, or None: Blender's sys.path first, then `folder` (the add-on's
    preference), then the build tree's or install's module beside the add-on."""
    try:
        import nimbus
        return nimbus
    except ImportError:
        pass
    for candidate in (folder, _layout()[0]):
        if candidate and os.path.isdir(os.path.join(candidate, "nimbus")):
            if candidate not in sys.path:
                sys.path.append(candidate)
            try:
                import nimbus
                return nimbus
            except ImportError:
                sys.path.remove(candidate)
    return None


def find_executable(preference=""):
    """The nimbus executable: the preference, then the one beside the add-on, then PATH."""
    for candidate in (preference, _layout()[1]):
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    return shutil.which("nimbus")


def pass_ends(spp):
    """Sample counts after each progressive pass: 1, 2, 4, ... up to spp (each pass doubles the
    samples, so the passes cost at most twice the last one's and the first pixel comes fast)."""
    ends, n = [], 1
    while n < spp:
        ends.append(n)
        n *= 2
    ends.append(spp)
    return ends


def render_progressive(nimbus, scene, film, spp, should_stop, on_pass, threads=None):
    """Adds samples [0, spp) to `film` in passes (pass_ends), calling on_pass(film, samples) after
    each. should_stop() is asked about every 50 ms while a pass runs; when it says so, the pass
    is dropped and this returns the samples the film holds. Otherwise returns spp. Consecutive
    ranges give the bits of one render (docs/python.md), so the result is `nimbus render`'s."""
    def progress(done, total):
        if should_stop():
            raise Cancelled()

    start = 0
    for end in pass_ends(spp):
        if should_stop():
            return start
        try:
            nimbus.render_into(scene, film, (start, end), threads=threads, progress=progress)
        except Cancelled:
            return start
        start = end
        on_pass(film, end)
    return spp


def render_with_executable(executable, document, should_stop, poll_seconds=0.05):
    """Renders `document` with `nimbus render` in a temporary folder; returns the EXR's path and
    the folder (the caller removes it), or (None, folder) when stopped. Raises RuntimeError with
    nimbus's own line when it fails."""
    folder = tempfile.mkdtemp(prefix="nimbus-blender-")
    scene_path = os.path.join(folder, "scene.json")
    image_path = os.path.join(folder, "render.exr")
    with open(scene_path, "w", encoding="utf-8") as f:
        json.dump(document, f, indent=1)
    log_path = os.path.join(folder, "render.log")
    with open(log_path, "w", encoding="utf-8") as log:
        process = subprocess.Popen([executable, "render", scene_path, "-q", "-o", image_path],
                                   stdout=subprocess.DEVNULL, stderr=log)
    while True:
        try:
            process.wait(timeout=poll_seconds)
            break
        except subprocess.TimeoutExpired:
            if should_stop():
                process.terminate()
                process.wait()
                return None, folder
    with open(log_path, encoding="utf-8", errors="replace") as log:
        message = log.read().strip()
    if process.returncode != 0:
        raise RuntimeError(message.splitlines()[-1] if message else
                           f"nimbus render exited with status {process.returncode}")
    return image_path, folder
