"""The 3D page (`proxseg view`, io/view_page.hpp) in a real browser: headless Chromium
(tests/chromium.py) loads the pages of a segmentation and a recognition with no console error,
draws the cloud, lists the report's objects in the legend and names the object under a click."""

import json
import subprocess
import time

import pytest

from batch_log import failed, ms_of, write_batch_log
from chromium import Browser
from conftest import CLI, data, run_cli, scene_folder, ycb_frame

# A drawn pixel: brighter than the page's background (0.07, 0.07, 0.09).
DRAWN_PIXELS = """(() => {
  const c = document.getElementById('view'), t = document.createElement('canvas');
  t.width = c.width; t.height = c.height;
  const g = t.getContext('2d'); g.drawImage(c, 0, 0);
  const d = g.getImageData(0, 0, t.width, t.height).data;
  let n = 0;
  for (let i = 0; i < d.length; i += 4) if (d[i] + d[i + 1] + d[i + 2] > 80) ++n;
  return n / (t.width * t.height);
})()"""


@pytest.fixture(scope="module")
def browser():
    with Browser(width=1280, height=720) as b:
        yield b


def open_page(browser, page):
    started = time.monotonic()
    browser.open(page)
    first_draw_ms = browser.evaluate("proxsegView.ready.then(a => a.firstDrawMs)")
    return first_draw_ms, time.monotonic() - started


def click_object(browser, object_id):
    """Clicks a point of object_id where nothing hides it; returns the picked panel's text."""
    index = browser.evaluate(f"proxsegView.visiblePointOf({object_id})")
    assert index >= 0, f"no visible point of object {object_id}"
    browser.click(*browser.evaluate(f"proxsegView.screenOf({index})"))
    return browser.evaluate("proxsegView.info()")


def test_segmentation_page_draws_lists_and_picks_the_instances(tmp_path, browser):
    prefix = tmp_path / "learn0"
    run_cli("segment", data("mosd/learn/learn0.pcd"), "-o", prefix, "--outputs", "pcd,json")
    run_cli("view", prefix)
    page = prefix.with_suffix(".html")
    assert page.stat().st_size <= 3 << 20, f"{page}: {page.stat().st_size} bytes"
    first_draw_ms, seconds = open_page(browser, page)
    assert first_draw_ms < 5000 and seconds < 10, (first_draw_ms, seconds)
    assert browser.evaluate("proxsegView.layers()") == ["colour", "label", "instance"]
    assert browser.evaluate(DRAWN_PIXELS) > 0.2
    # Turning draws every step-th point when a frame of all of them is slow (software WebGL
    # here), and all of them again once the view rests.
    moving = browser.evaluate("proxsegView.moving")
    points = browser.evaluate("proxsegView.meta.points")
    browser.evaluate("proxsegView.drawnPoints()")
    browser.drag([(640 + 15 * k, 360) for k in range(8)])
    drawn, deadline = [], time.monotonic() + 10
    while not drawn or drawn[-1] != points:  # until the view rests
        assert time.monotonic() < deadline, drawn
        time.sleep(0.1)
        drawn += browser.evaluate("proxsegView.drawnPoints()")
    if moving["step"] > 1:
        assert -(-points // moving["step"]) in drawn, (moving, drawn)
    else:
        assert set(drawn) == {points}, (moving, drawn)
    report = json.loads(prefix.with_suffix(".json").read_text())
    instances = {c["id"] for c in report["candidates"] + report["background"]}
    legend = browser.evaluate("proxsegView.legend()")
    assert {e["id"] for e in legend} == instances
    candidate = report["candidates"][0]["id"]
    text = click_object(browser, candidate)
    assert text.startswith(f"id{candidate}namecandidate"), text
    browser.evaluate("proxsegView.setLayer('colour')")
    assert browser.evaluate(DRAWN_PIXELS) > 0.2
    assert browser.errors() == []


def test_recognition_page_names_the_objects_and_draws_their_boxes(tmp_path, ycb_db, browser):
    prefix = tmp_path / "ycb"
    f = ycb_frame(1)
    run_cli("recognize", "--color", f["color"], "--depth", f["depth"], "--meta", f["meta"],
            "--db", ycb_db, "-o", prefix, "--outputs", "pcd,json")
    run_cli("view", prefix, "--title", "YCB-Video 000001")
    page = prefix.with_suffix(".html")
    assert page.stat().st_size <= 3 << 20
    open_page(browser, page)
    assert browser.evaluate("document.title") == "proxseg: YCB-Video 000001"
    report = json.loads(prefix.with_suffix(".json").read_text())
    legend = browser.evaluate("proxsegView.legend()")
    assert legend == [{"id": c["id"], "name": c["name"]} for c in report["candidates"]]
    named = [c for c in report["candidates"] if c["name"] != "unknown"]
    assert named, "the frame's objects were not recognised"
    boxes = browser.evaluate("proxsegView.meta.objects.map(o => o.name)")
    assert boxes == [c["name"] for c in named]
    for c in named:
        text = click_object(browser, c["id"])
        assert f"name{c['name']}score{c['score']:.3f}" in text, text
        assert "pose" in text
    assert browser.errors() == []


def test_view_refuses_what_is_not_a_result(tmp_path):
    for args, expected in [((tmp_path / "none",), "none.json: file not found"),
                           ((tmp_path,), "no summary.jsonl (expected the folder of a --batch")]:
        r = subprocess.run([CLI, "view", *map(str, args)], capture_output=True, text=True)
        assert r.returncode == 1 and expected in r.stderr, r.stderr
    (tmp_path / "x.json").write_text('{"not": "a report"}')
    r = subprocess.run([CLI, "view", str(tmp_path / "x")], capture_output=True, text=True)
    assert r.returncode == 1 and "not a report of proxseg" in r.stderr, r.stderr
    assert not (tmp_path / "x.html").exists()


def test_batch_page_lists_sorts_and_filters_the_frames(tmp_path, browser):
    frames = scene_folder(tmp_path / "frames", (1, 2, 10))
    out = tmp_path / "out"
    r = subprocess.run([CLI, "segment", "--batch", str(frames), "-o", str(out), "-q",
                        "--outputs", "png,json,html"], capture_output=True, text=True)
    assert r.returncode == 1, r.stderr  # one frame failed
    run_cli("view", out)
    browser.open(out / "index.html")
    browser.evaluate("new Promise(ok => requestAnimationFrame(() => ok()))")
    assert browser.evaluate("proxsegBatch.total()") == 4
    assert browser.evaluate("proxsegBatch.shown()") == ["broken", "learn1", "learn2", "learn10"]
    browser.evaluate("proxsegBatch.setStatus('failed')")
    assert browser.evaluate("proxsegBatch.shown()") == ["broken"]
    text = browser.evaluate("document.querySelector('.card.failed').textContent")
    assert "broken.pcd" in text, text
    browser.evaluate("proxsegBatch.setStatus('all')")
    browser.evaluate("proxsegBatch.setFilter('learn1')")
    assert browser.evaluate("proxsegBatch.shown()") == ["learn1", "learn10"]
    browser.evaluate("proxsegBatch.setFilter('')")
    browser.evaluate("proxsegBatch.setSort('time-')")
    rows = {json.loads(line)["frame"]: json.loads(line) for line in
            (out / "summary.jsonl").read_text().splitlines()[1:-1]}
    slowest = sorted((r for r in rows.values() if "error" not in r), key=lambda r: -r["ms"])
    assert browser.evaluate("proxsegBatch.shown()")[:3] == [r["frame"] for r in slowest]
    links = browser.evaluate("[...document.querySelectorAll('.card a')].map(a => a.href)")
    assert sorted(link.rsplit("/", 1)[1] for link in links) == ["learn1.html", "learn10.html",
                                                                "learn2.html"]
    assert browser.errors() == []


def test_batch_page_of_ten_thousand_frames_opens_at_once(tmp_path, browser):
    """A generated log of 10,000 frames (every 50th failed): the page shows the first 60 and
    pages through the rest."""
    out = write_batch_log(tmp_path / "big", 10000)
    run_cli("view", out)
    started = time.monotonic()
    browser.open(out / "index.html")
    browser.evaluate("new Promise(ok => requestAnimationFrame(() => ok()))")
    seconds = time.monotonic() - started
    assert browser.evaluate("proxsegBatch.firstDrawMs") < 3000 and seconds < 10, seconds
    assert browser.evaluate("proxsegBatch.total()") == 10000
    assert browser.evaluate("proxsegBatch.shown()")[:3] == ["scene0", "scene1", "scene2"]
    browser.evaluate("proxsegBatch.nextPage()")
    assert browser.evaluate("proxsegBatch.shown()")[0] == "scene60"
    browser.evaluate("proxsegBatch.setMinCount(8)")  # the frames with 8 candidates
    expected = [k for k in range(10000) if not failed(k) and k % 9 >= 8]
    assert browser.evaluate("proxsegBatch.shown()")[:2] == [f"scene{k}" for k in expected[:2]]
    browser.evaluate("proxsegBatch.setMinTime(140)")  # and at least 140 ms
    slow = [k for k in expected if ms_of(k) >= 140]
    assert browser.evaluate("document.getElementById('position').textContent") == \
        f"1-60 of {len(slow)} frames (10000 in all)"
    browser.evaluate("proxsegBatch.setMinCount(0)")
    browser.evaluate("proxsegBatch.setMinTime(0)")
    browser.evaluate("proxsegBatch.setStatus('failed')")
    assert len(browser.evaluate("proxsegBatch.shown()")) == 60
    assert browser.evaluate("document.getElementById('position').textContent") == \
        "1-60 of 200 frames (10000 in all)"
    assert browser.errors() == []


def test_batch_page_of_two_hundred_thousand_frames_draws_its_plots(tmp_path, browser):
    """Past about 150,000 frames spreading the times into Math.min overflowed the stack: the
    page must show them all with no script error."""
    out = write_batch_log(tmp_path / "huge", 200000)
    run_cli("view", out)
    browser.open(out / "index.html")
    browser.evaluate("new Promise(ok => requestAnimationFrame(() => ok()))")
    assert browser.errors() == []
    assert browser.evaluate("proxsegBatch.total()") == 200000
    assert browser.evaluate("document.querySelector('#time-plot .range').textContent") == \
        "50 ms … 146 ms"


def test_python_results_show_the_same_page(tmp_path, ycb_db, browser):
    import proxseg

    frame = proxseg.read_point_cloud(str(data("mosd/learn/learn0.pcd")))
    r = proxseg.segment(frame, preset="paper")
    page = r.to_html(title="learn0")
    assert page.startswith("<!doctype html>") and "proxseg-meta" in page
    assert r._repr_html_().startswith("<iframe srcdoc=\"&lt;!doctype html&gt;")
    path = r.show(tmp_path / "learn0.html", browser=False)
    browser.open(path)
    browser.evaluate("proxsegView.ready")
    # The paper preset's labels: k-means, then MRF [3.2], beside the scene's colours.
    assert browser.evaluate("proxsegView.layers()") == ["colour", "label_kmeans", "label",
                                                       "instance"]
    assert browser.evaluate("proxsegView.meta.layers.map(l => l.title)")[1:3] == [
        "k-means labels", "MRF labels"]
    f = ycb_frame(1)
    scene = proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"])
    rec = proxseg.recognize(scene, proxseg.Database(str(ycb_db)))
    browser.open(rec.show(tmp_path / "ycb.html", browser=False))
    browser.evaluate("proxsegView.ready")
    assert [e["name"] for e in browser.evaluate("proxsegView.legend()")] == rec.names
    assert browser.errors() == []


def test_show_opens_the_file_it_wrote_whatever_its_name(tmp_path, monkeypatch):
    """show()'s URL is the path percent-encoded (Path.as_uri): a '#', '?', '%' or byte that is
    not UTF-8 in the path opens that file, not another one or a fragment (issue 54)."""
    import os
    import webbrowser
    from urllib.parse import unquote_to_bytes, urlsplit

    from proxseg import _page

    opened = []
    monkeypatch.setattr(webbrowser, "open", opened.append)
    for name in ["a#b.html", "q?x=1.html", "%41.html", "sp ace.html", os.fsdecode(b"bad\xff.html")]:
        path = _page.show("<p>x</p>", tmp_path / name)
        url = urlsplit(opened[-1])
        assert url.scheme == "file" and not url.query and not url.fragment, opened[-1]
        assert unquote_to_bytes(url.path) == os.fsencode(os.path.abspath(path)), opened[-1]

