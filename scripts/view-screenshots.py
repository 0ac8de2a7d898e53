#!/usr/bin/env python3
"""Makes the screenshots of the pages in README.md and docs/viewing.md (docs/img/view-*.*):
a recognised YCB-Video frame with its legend and boxes, an mOSD scene's instances and a batch
page, each written by the built CLI and taken in headless Chromium (python/tests/chromium.py).
Usage: scripts/view-screenshots.py [BUILD] [DATA]   (BUILD: build, DATA: ../shared/data)"""

import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python" / "tests"))
from chromium import Browser  # noqa: E402

build = Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "build")
data = Path(sys.argv[2] if len(sys.argv) > 2 else ROOT.parent / "shared" / "data")
cli = str(build / "proxseg")
img = ROOT / "docs" / "img"


def run(*args):
    subprocess.run([cli, *map(str, args), "-q"], check=True, stdout=subprocess.DEVNULL)


with tempfile.TemporaryDirectory() as tmp:
    t = Path(tmp)
    for name in ("009_gelatin_box", "025_mug", "061_foam_brick"):
        run("db", "add", t / "db", "--name", name, "--xyz", data / f"ycbv/models/{name}/points.xyz")
    frame = data / "ycbv/frames/000001"
    run("recognize", "--color", f"{frame}-color.png", "--depth", f"{frame}-depth.png", "--meta",
        f"{frame}-meta.json", "--db", t / "db", "-o", t / "ycb-000001", "--outputs", "html,json")
    run("segment", data / "mosd/learn/learn40.pcd", "-o", t / "learn40", "--outputs", "html,json")
    (t / "scenes").mkdir()
    for k in (0, 3, 7, 12, 18, 22, 25, 29, 33, 36, 40, 44):
        (t / "scenes" / f"learn{k}.pcd").symlink_to(data / f"mosd/learn/learn{k}.pcd")
    run("segment", "--batch", t / "scenes", "-o", t / "batch", "--outputs", "png,json,html")
    run("view", t / "batch", "--title", "mOSD learn (12 scenes)")
    with Browser(1280, 720) as b:
        b.open(t / "ycb-000001.html")
        b.evaluate("proxsegView.ready")
        point = b.evaluate("proxsegView.visiblePointOf(7)")  # the gelatin box: picked, hovered
        x, y = b.evaluate(f"proxsegView.screenOf({point})")
        b.click(x, y)
        b.hover(x, y)
        time.sleep(0.3)
        b.screenshot(img / "view-ycb.png")
        b.open(t / "learn40.html")
        b.evaluate("proxsegView.ready")
        b.screenshot(img / "view-mosd.png")
        b.open(t / "batch" / "index.html")
        time.sleep(1.5)  # the pictures load lazily
        b.screenshot(img / "view-batch.jpg")
        assert b.errors() == [], b.errors()
print("docs/img/view-ycb.png, view-mosd.png, view-batch.jpg")
