"""Headless Chromium for the page tests, driven over the DevTools protocol on a pipe
(--remote-debugging-pipe: JSON messages ending in a NUL byte, commands on fd 3, answers on
fd 4), so that no driver beyond Debian's chromium package is needed. It records the page's
console errors and uncaught exceptions, evaluates script, sends mouse events and takes
screenshots."""

from __future__ import annotations

import base64
import fcntl
import json
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

# As the machines here need them: no GPU (WebGL by SwiftShader), no network traffic of its own.
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-extensions", "--mute-audio", "--hide-scrollbars"]


def _above_ten(fd: int) -> int:
    high = fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10)
    os.close(fd)
    return high


def executable() -> str:
    path = shutil.which("chromium") or shutil.which("chromium-browser")
    assert path, "chromium: not found (scripts/install-deps.sh installs Debian's chromium)"
    return path


class Browser:
    """One headless Chromium with one page, width x height CSS pixels."""

    def __init__(self, width: int = 1280, height: int = 720, timeout: float = 60) -> None:
        self.timeout = timeout
        self.profile = tempfile.mkdtemp(prefix="proxseg-chromium-")
        commands, self._out = os.pipe()
        self._in, answers = os.pipe()
        # Above fd 10 first, so that moving them onto 3 and 4 in the child clobbers neither.
        commands, answers = (_above_ten(fd) for fd in (commands, answers))

        def wire() -> None:  # in the child: the commands on fd 3, the answers on fd 4
            os.dup2(commands, 3)
            os.dup2(answers, 4)

        # close_fds=False: fds 3 and 4 must stay open across exec (os.pipe's fds do not: they
        # are not inheritable).
        self.process = subprocess.Popen(
            [executable(), *FLAGS, "--remote-debugging-pipe", f"--user-data-dir={self.profile}",
             f"--window-size={width},{height}", "about:blank"],
            close_fds=False, preexec_fn=wire,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        to_child, from_child = commands, answers
        os.close(to_child)
        os.close(from_child)
        self._buffer = b""
        self._next_id = 0
        self.events: List[Dict[str, Any]] = []
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=target,
                                 flatten=True)["sessionId"]
        for domain in ("Page", "Runtime", "Log"):
            self.call(f"{domain}.enable", session=True)
        self.call("Emulation.setDeviceMetricsOverride", session=True, width=width,
                  height=height, deviceScaleFactor=1, mobile=False)

    # ---- the protocol ----
    def _read_message(self, deadline: float) -> Dict[str, Any]:
        while b"\0" not in self._buffer:
            if time.monotonic() > deadline:
                raise TimeoutError("chromium did not answer in time")
            chunk = os.read(self._in, 1 << 20)
            if not chunk:
                raise RuntimeError("chromium closed its pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, session: bool = False, **params: Any) -> Dict[str, Any]:
        """Sends a command (to the page's session when session is true) and returns its result;
        events that arrive meanwhile are kept in self.events."""
        self._next_id += 1
        message: Dict[str, Any] = {"id": self._next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = self.session
        os.write(self._out, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + self.timeout
        while True:
            answer = self._read_message(deadline)
            if answer.get("id") == self._next_id:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error']}")
                return answer.get("result", {})
            self.events.append(answer)

    # ---- what the tests use ----
    def open(self, path: Path) -> None:
        self.call("Page.navigate", session=True, url=Path(path).resolve().as_uri())
        deadline = time.monotonic() + self.timeout
        while self.evaluate("document.readyState") != "complete":
            if time.monotonic() > deadline:
                raise TimeoutError(f"{path}: did not load")
            time.sleep(0.05)

    def evaluate(self, expression: str) -> Any:
        """The value of expression in the page (a promise is awaited); an exception in it fails."""
        result = self.call("Runtime.evaluate", session=True, expression=expression,
                           awaitPromise=True, returnByValue=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression}: {result['exceptionDetails']}")
        return result["result"].get("value")

    def click(self, x: float, y: float) -> None:
        for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", session=True, type=kind, x=x, y=y,
                      button="left" if kind != "mouseMoved" else "none", clickCount=1)

    def drag(self, points: List[Tuple[float, float]]) -> None:
        """Presses the left button at the first point, moves through the others, releases it at
        the last."""
        x, y = points[0]
        self.call("Input.dispatchMouseEvent", session=True, type="mousePressed", x=x, y=y,
                  button="left", clickCount=1)
        for x, y in points[1:]:
            self.call("Input.dispatchMouseEvent", session=True, type="mouseMoved", x=x, y=y,
                      button="left")
        self.call("Input.dispatchMouseEvent", session=True, type="mouseReleased", x=x, y=y,
                  button="left", clickCount=1)

    def hover(self, x: float, y: float) -> None:
        self.call("Input.dispatchMouseEvent", session=True, type="mouseMoved", x=x, y=y)

    def screenshot(self, path: Path) -> None:
        """The page as PNG, or JPEG (quality 85) when path ends in .jpg."""
        jpeg = str(path).endswith(".jpg")
        data = self.call("Page.captureScreenshot", session=True,
                         **({"format": "jpeg", "quality": 85} if jpeg else {"format": "png"}))["data"]
        Path(path).write_bytes(base64.b64decode(data))

    def errors(self) -> List[str]:
        """The console's errors and the uncaught exceptions so far."""
        out = []
        for e in self.events:
            p = e.get("params", {})
            if e.get("method") == "Runtime.exceptionThrown":
                out.append(str(p.get("exceptionDetails", {}).get("exception", p)))
            elif e.get("method") == "Runtime.consoleAPICalled" and p.get("type") == "error":
                out.append(" ".join(str(a.get("value", a.get("description"))) for a in p["args"]))
            elif e.get("method") == "Log.entryAdded" and p["entry"]["level"] == "error":
                out.append(p["entry"]["text"])
        return out

    def close(self) -> None:
        try:
            self.call("Browser.close")
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
        for fd in (self._in, self._out):
            os.close(fd)
        shutil.rmtree(self.profile, ignore_errors=True)

    def __enter__(self) -> "Browser":
        return self

    def __exit__(self, *exc: Optional[object]) -> None:
        self.close()
