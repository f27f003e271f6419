"""The Python module loads OpenVDB only for a scene that reads a VDB file (issue 45): the grid is
read by nimbus_openvdb.so, which _core finds beside the build tree's executables or in the
install's libdir and loads on first use. A module that cannot be loaded is a SceneError naming it
for that scene, and nothing else.

Each case runs in a fresh interpreter: a process maps a library once and keeps it."""
import os
import subprocess
import sys

SOURCE = os.environ.get("NIMBUS_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))

SCRIPT = r"""
import sys
import nimbus
def mapped():
    with open("/proc/self/maps") as f:
        return "libopenvdb" in f.read()
scene = nimbus.load_file(sys.argv[1], {"film.width": 8, "film.height": 6})
try:
    nimbus.render(scene, spp=1)
    print("rendered", mapped())
except nimbus.SceneError as e:
    print("SceneError", mapped(), e)
"""


def run(scene, env=None):
    out = subprocess.run([sys.executable, "-c", SCRIPT, os.path.join(SOURCE, "scenes", scene)],
                         capture_output=True, text=True, timeout=120,
                         env=dict(os.environ, **(env or {})))
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


def test_only_a_vdb_scene_loads_openvdb():
    assert run("demo.json") == "rendered False"
    assert run("vdb_fire.json") == "rendered True"


def test_a_module_that_cannot_be_loaded_is_a_scene_error_for_vdb_scenes_only(tmp_path):
    env = {"NIMBUS_OPENVDB_MODULE": str(tmp_path / "missing.so")}
    assert run("demo.json", env) == "rendered False"
    line = run("vdb_fire.json", env)
    assert line.startswith("SceneError False "), line
    assert "needs nimbus's OpenVDB module: cannot load " + str(tmp_path / "missing.so") in line
