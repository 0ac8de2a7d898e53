#!/usr/bin/env python3
"""The batch page in a real browser with hostile frame names (issue 54, point 2): a batch whose
frames are named like a javascript: URL, with '#', '%', '?', spaces, quotes, markup, text that
is not ASCII, bytes that are not UTF-8, a subfolder and "summary" (its files renamed
summary-frame.*), each a copy of one tiny scene, opened by headless Chromium
(python/tests/chromium.py, over its DevTools pipe). No script of a name runs, every picture
loads, and every link, clicked as a user clicks it, opens the file the batch wrote.

Usage: batch_links_test.py PROXSEG SOURCE_DIR. Exit 0 when all holds, 1 with what did not, 77
(ctest's SKIP_RETURN_CODE) when there is no chromium."""

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import unquote_to_bytes, urlsplit

SKIP = 77
# The frames, as bytes (file names are bytes): each is copied from one synthetic scene.
NAMES = [b"javascript:alert(document.domain)", b"javascript:document.title='pwned';[]",
         b"a#b", b"50%", b"%41", b"q?x=1", b"sp ace", b"quote\"'<&>",
         "\u00fcn\u00ef".encode(), b"bad\xff", b"d#ir/j:s", b"summary"]

# Every picture loaded or failed (lazy ones too: the window is tall enough to show them all).
PICTURES = """Promise.all([...document.images].map(i => i.complete ? 0
  : new Promise(r => { i.onload = i.onerror = r; }))).then(() =>
  [...document.images].map(i => [i.getAttribute('src'), i.src, i.naturalWidth]))"""
# Each link: its attribute and the URL the browser made of it.
LINKS = "[...document.querySelectorAll('a')].map(a => [a.getAttribute('href'), a.href])"
# Where to click the link numbered %d: its middle, once scrolled into view.
PLACE = """(() => { const a = document.querySelectorAll('a')[%d];
  a.scrollIntoView({block: 'center'});
  const r = a.getBoundingClientRect();
  return [r.x + r.width / 2, r.y + r.height / 2]; })()"""


def write_tiny_scene(path: Path) -> None:
    """A scene small enough to segment in a few milliseconds: 64x48 points of a grey table and
    a red box in front of it (ASCII PCD)."""
    points = []
    for v in range(48):
        for u in range(64):
            box = 20 <= u < 40 and 14 <= v < 30
            z = 0.8 if box else 1.0 + 0.004 * v
            points.append(f"{(u - 32) * z / 60:.5f} {(v - 24) * z / 60:.5f} {z:.5f} "
                          f"{0xC81E1E if box else 0x787878}")
    path.write_text("VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
                    "WIDTH 64\nHEIGHT 48\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3072\nDATA ascii\n"
                    + "\n".join(points) + "\n")


def batch(cli: str, tmp: Path) -> Path:
    """OUT of `segment --batch IN -o OUT --outputs png,html` and `view OUT` on NAMES."""
    scene, into, out = tmp / "scene.pcd", os.fsencode(tmp / "IN"), tmp / "OUT"
    write_tiny_scene(scene)
    for name in NAMES:
        path = os.path.join(into, name + b".pcd")
        os.makedirs(os.path.dirname(path), exist_ok=True)
        shutil.copyfile(scene, path)
    for args in (["segment", "--batch", os.fsdecode(into), "-o", str(out), "-q",
                  "--outputs", "png,html"], ["view", str(out), "-q"]):
        subprocess.run([cli, *args], check=True, capture_output=True)
    return out


def file_of(url: str, out: Path) -> bytes:
    """The file (its bytes) a URL of OUT names, b"" when it names none: a file: URL under OUT
    with neither query nor fragment, percent-decoded as the browser decodes it."""
    parts = urlsplit(url)
    base = out.resolve().as_uri() + "/"
    if parts.scheme != "file" or parts.query or parts.fragment or not url.startswith(base):
        return b""
    path = unquote_to_bytes(parts.path)
    return path if os.path.isfile(path) else b""


def click(browser, x: float, y: float, seconds: float = 3) -> tuple:
    """Clicks at (x, y) and waits for what it did: ("dialog", text) when a script opened a
    dialog, ("title", t) when a script set the page's title, ("opened", url) when another
    document loaded, ("nothing", "") when none came in time."""
    browser.events.clear()
    browser.click(x, y)
    deadline, url = time.monotonic() + seconds, None
    while time.monotonic() < deadline:
        # A call to the browser, not the page: it answers while a dialog holds the page.
        targets = browser.call("Target.getTargets")["targetInfos"]
        for e in browser.events:
            method, p = e.get("method"), e.get("params", {})
            if method == "Page.javascriptDialogOpening":
                browser.call("Page.handleJavaScriptDialog", session=True, accept=True)
                return ("dialog", p.get("message", ""))
            if method == "Page.frameNavigated" and not p["frame"].get("parentId"):
                url = p["frame"]["url"]
            if method == "Page.loadEventFired" and url:
                return ("opened", url)
        if any(t.get("title") == "pwned" for t in targets):
            return ("title", "pwned")
        time.sleep(0.02)
    return ("nothing", "")


def check(browser, out: Path) -> list:
    """What is wrong with the batch page of OUT in the browser (nothing: [])."""
    wrong, index = [], out / "index.html"
    browser.open(index)
    pictures = browser.evaluate(PICTURES)
    if len(pictures) != len(NAMES):
        wrong.append(f"{len(pictures)} pictures for {len(NAMES)} frames")
    for src, url, width in pictures:
        if not src.startswith("./"):
            wrong.append(f"picture {src!r}: not relative (./)")
        if not file_of(url, out) or not width:
            wrong.append(f"picture {src!r}: {url} is no file of the batch, or did not load")
    links = browser.evaluate(LINKS)
    if len(links) != len(NAMES):
        wrong.append(f"{len(links)} links for {len(NAMES)} frames")
    for number, (href, url) in enumerate(links):
        if not href.startswith("./"):
            wrong.append(f"link {href!r}: not relative (./)")
        if not file_of(url, out):
            wrong.append(f"link {href!r}: {url} is no file of the batch")
        browser.open(index)
        what, detail = click(browser, *browser.evaluate(PLACE % number))
        opened = file_of(detail, out) if what == "opened" else b""
        if not opened or opened != file_of(url, out):
            wrong.append(f"clicking link {href!r}: {what} {detail!r}")
    browser.open(index)
    if browser.evaluate("document.title") != "proxseg: OUT":
        wrong.append("the page's title changed: " + browser.evaluate("document.title"))
    return wrong


def main(argv: list) -> int:
    cli, source = argv[1], Path(argv[2])
    if not (shutil.which("chromium") or shutil.which("chromium-browser")):
        print("SKIPPED: chromium not found (scripts/install-deps.sh installs Debian's chromium):"
              " the batch page's links were not tried in a browser")
        return SKIP
    sys.path.insert(0, str(source / "python" / "tests"))
    from chromium import Browser  # pylint: disable=import-outside-toplevel

    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="proxseg-links-") as tmp:
        out = batch(cli, Path(tmp))
        with Browser(width=1280, height=2400, timeout=20) as browser:
            wrong = check(browser, out)
    for w in wrong:
        print("FAILED:", w)
    print(f"{len(NAMES)} frames, {'ok' if not wrong else 'wrong'} in"
          f" {time.monotonic() - started:.1f} s")
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
