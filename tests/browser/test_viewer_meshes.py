"""nimbus view's instant preview (issue 43, item 4): once the page has the scene's meshes, a drag
is drawn by the page itself, with the server stopped (SIGSTOP), so before any path-traced pass of
the new view can arrive: the picture changes with the camera, and its silhouette is that of
`nimbus render` of the same camera within two pixels."""
import base64
import io
import json
import os
import signal
import subprocess
import time

import numpy
import pytest
from PIL import Image

import cdp
from test_viewer import EXE, Viewer

SCENE = {
    "film": {"width": 160, "height": 100},
    "camera": {"type": "perspective", "from": [0.5, 1.5, 7], "to": [0, 0, 0], "fov": 40},
    # Many samples: the path tracer is far from done while the test runs.
    "integrator": {"spp": 100000, "seed": 1},
    "objects": [
        {"shape": {"type": "sphere", "center": [-1.2, 0, 0], "radius": 1},
         "surface": {"type": "emissive", "radiance": 1}},
        # A box turned off the grid's axes: its sharp edges are bisected (docs/meshes.md).
        {"shape": {"type": "box", "min": [0.3, -0.8, -0.7], "max": [1.9, 0.6, 0.7],
                   "transform": [{"rotate": {"axis": [1, 1, 0], "degrees": 20}}]},
         "surface": {"type": "emissive", "radiance": 1}}],
}

IMAGE_RECT = """(() => {
  const r = document.getElementById('image').getBoundingClientRect();
  return [r.x, r.y, r.width, r.height];
})()"""


def canvas_silhouette(browser):
    """The meshes' canvas as on screen (over the image): where it is not the black background."""
    x, y, w, h = browser.evaluate(IMAGE_RECT)
    data = browser.call("Page.captureScreenshot", {
        "format": "png", "clip": {"x": x, "y": y, "width": w, "height": h, "scale": 1}})["data"]
    rgb = numpy.asarray(Image.open(io.BytesIO(base64.b64decode(data))).convert("RGB"), float)
    # The meshes are lit at least a quarter, 0.25^(1/2.2) of white: half of that is inside.
    return rgb.max(axis=2) > 0.5 * 255 * 0.25 ** (1 / 2.2)


def render_silhouette(tmp_path, camera, name):
    scene = dict(SCENE, camera=camera, integrator={"spp": 16, "seed": 1})
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(scene))
    out = tmp_path / f"{name}.png"
    subprocess.run([EXE, "render", str(path), "-o", str(out), "--quiet"], check=True)
    rgb = numpy.asarray(Image.open(out).convert("RGB"), float)
    return rgb.max(axis=2) > 127


def shift_any(mask, r):
    """Where mask holds within r pixels (a square neighbourhood)."""
    out = numpy.zeros_like(mask)
    h, w = mask.shape
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            out[max(dy, 0):h + min(dy, 0), max(dx, 0):w + min(dx, 0)] |= \
                mask[max(-dy, 0):h + min(-dy, 0), max(-dx, 0):w + min(-dx, 0)]
    return out


def assert_same_silhouette(seen, expected, what):
    assert seen.shape == expected.shape, what
    # A pixel may differ only within two pixels of the rendered silhouette's edge.
    edge = expected ^ ~shift_any(~expected, 1)
    off = (seen ^ expected) & ~shift_any(edge, 2)
    assert off.sum() == 0, f"{what}: {off.sum()} pixels beyond 2 of the edge, at {numpy.argwhere(off)[:5]}"
    assert 0.05 < expected.mean() < 0.8, f"{what}: the objects cover {expected.mean():.2f} of the view"


@pytest.mark.parametrize("camera", [
    SCENE["camera"],
    {"type": "orthographic", "from": [0.5, 1.5, 7], "to": [0, 0, 0], "width": 6}])
def test_the_page_draws_a_camera_move_from_its_meshes_without_the_server(tmp_path, camera):
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(dict(SCENE, camera=camera)))
    viewer = Viewer(str(scene))
    browser = cdp.Browser()
    stopped = False
    try:
        browser.navigate(viewer.url)
        browser.wait_for("window.nimbusView && nimbusView.meshes() && nimbusView.meshes().meshes > 0",
                         timeout=120, what="the meshes")
        state = viewer.state()
        assert state["meshes"] == 1 and state["mesh_triangles"] > 1000, state
        os.kill(viewer.process.pid, signal.SIGSTOP)
        stopped = True
        x, y, w, h = browser.evaluate(IMAGE_RECT)
        cameras, silhouettes = [], []
        for dx, dy in ((60, 10), (-40, 25)):
            frames = browser.evaluate("nimbusView.meshes().frames")
            browser.drag(x + w / 2, y + h / 2, x + w / 2 + dx, y + h / 2 + dy)
            browser.wait_for(f"nimbusView.meshes().frames > {frames} && "
                             "!document.getElementById('meshes').hidden", what="a drawn frame")
            time.sleep(0.3)  # the last move's frame on screen
            cameras.append(browser.evaluate("nimbusView.camera()"))
            silhouettes.append(canvas_silhouette(browser))
        assert cameras[0]["from"] != cameras[1]["from"]
        assert (silhouettes[0] ^ silhouettes[1]).sum() > 200, "the picture did not follow the drag"
    finally:
        if stopped:
            os.kill(viewer.process.pid, signal.SIGCONT)
        browser.close()
        code, err = viewer.stop()
    assert code == 0 and err == "", err
    for i, (moved, seen) in enumerate(zip(cameras, silhouettes)):
        assert_same_silhouette(seen, render_silhouette(tmp_path, moved, f"view{i}"), f"view {i}")
