#!/usr/bin/env python3
"""The README's picture of `nimbus view`: serves SCENE, opens the page in headless Chromium
(tests/browser/cdp.py), waits until the render is done and writes a screenshot.

Usage: tools/viewer_screenshot.py NIMBUS SCENE OUT.png [nimbus view options...]
"""
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "browser"))
import cdp  # noqa: E402


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    nimbus, scene, out = sys.argv[1:4]
    p = subprocess.Popen([nimbus, "view", scene, "--port", "0", *sys.argv[4:]],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    m = re.search(r"http://127\.0\.0\.1:(\d+)/", p.stdout.readline())
    if not m:
        sys.exit(f"viewer_screenshot: the viewer did not start: {p.stderr.read().strip()}")
    browser = cdp.Browser(width=1180, height=440)
    try:
        browser.navigate(f"http://127.0.0.1:{m.group(1)}/")
        browser.wait_for("document.getElementById('mode').textContent === 'done' && "
                         "+document.getElementById('image').dataset.version === state.version",
                         timeout=3600, what="the render to finish")
        browser.screenshot(out)
    finally:
        browser.close()
        p.send_signal(2)
        p.communicate(timeout=60)


if __name__ == "__main__":
    main()
