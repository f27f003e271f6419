#!/usr/bin/env python3
"""The viewer's instant preview (docs/benchmarks.md, "Viewer preview"): for each scene, `nimbus
view` in headless Chromium (Debian's; tests/browser/cdp.py drives it), and

  meshes      how long the server took to mesh the scene, its triangles and bytes;
  first frame seconds from starting `nimbus view` (and opening the page at once) to the first
              frame drawn from the meshes;
  draw        milliseconds to draw one frame of an orbit, waited for (median of the frames), and
  fps         frames drawn per second by the page's own animation loop over the orbit.

  /usr/bin/python3 bench/viewer_preview.py [--nimbus build/nimbus] [--seconds 4] SCENE...
"""
import argparse
import json
import os
import re
import signal
import subprocess
import sys
import time
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "browser"))
import cdp  # noqa: E402

ORBIT = """new Promise((done) => {
  const p = nimbusView.preview, c0 = nimbusView.camera();
  const w = %(w)d, h = %(h)d, seconds = %(seconds)f;
  const v = c0.from.map((x, i) => x - c0.to[i]);
  const draws = [];
  const start = performance.now();
  let frames = 0;
  function frame(now) {
    const a = 0.02 * frames;
    const from = [c0.to[0] + v[0] * Math.cos(a) + v[2] * Math.sin(a), c0.from[1],
                  c0.to[2] - v[0] * Math.sin(a) + v[2] * Math.cos(a)];
    const t0 = performance.now();
    p.draw({...c0, from}, w, h);
    p.finish();
    draws.push(performance.now() - t0);
    ++frames;
    if (now - start < 1000 * seconds) requestAnimationFrame(frame);
    else done({frames, seconds: (performance.now() - start) / 1000, draws});
  }
  requestAnimationFrame(frame);
})"""


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nimbus", default="build/nimbus")
    ap.add_argument("--seconds", type=float, default=4)
    ap.add_argument("scenes", nargs="+")
    args = ap.parse_args()
    print("| scene | triangles | mesh bytes | meshing (s) | first frame (s) | draw (ms, median) | fps |")
    print("|---|---|---|---|---|---|---|")
    for scene in args.scenes:
        start = time.monotonic()
        server = subprocess.Popen([args.nimbus, "view", scene, "--port", "0"],
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        port = re.search(r":(\d+)/", server.stdout.readline()).group(1)
        url = f"http://127.0.0.1:{port}/"
        browser = cdp.Browser(1600, 1000)
        try:
            browser.navigate(url)
            # The first frame: the page draws the meshes as soon as they arrive, or at once
            # when the camera moves; a zero-length move asks for it without changing the view.
            browser.wait_for("window.nimbusView && nimbusView.preview && nimbusView.preview.ready()",
                             timeout=600, what="the meshes")
            browser.evaluate("(() => { const s = nimbusView.meshes(); const c = nimbusView.camera();"
                             " const i = document.getElementById('image');"
                             " nimbusView.preview.draw(c, parseFloat(i.style.width),"
                             " parseFloat(i.style.height)); nimbusView.preview.finish(); })()")
            first = time.monotonic() - start
            state = json.loads(urllib.request.urlopen(url + "state").read())
            size = len(urllib.request.urlopen(url + "meshes.bin").read())
            # The orbit is the page's alone: the server, paused, takes no CPU from the drawing.
            server.send_signal(signal.SIGSTOP)
            r = browser.evaluate(ORBIT % {"w": state["width"], "h": state["height"],
                                          "seconds": args.seconds})
        finally:
            browser.close()
            server.send_signal(signal.SIGCONT)
            server.send_signal(signal.SIGINT)
            server.wait()
        print(f"| {os.path.basename(scene)} ({state['width']} × {state['height']}) "
              f"| {state['mesh_triangles']:,} | {size / 2**20:.1f} MiB | {state['mesh_seconds']:.2f} "
              f"| {first:.2f} | {median(r['draws']):.1f} | {r['frames'] / r['seconds']:.1f} |")


if __name__ == "__main__":
    main()
