"""The interpreter exits cleanly while proxseg computes on another thread: a daemon thread in
recognize() at sys.exit() or at Ctrl-C is stopped by the module's exit handler before the
interpreter finalizes (issue 54.6). Before, a call that ended while the interpreter finalized
aborted the process ("terminate called without an active exception", libgomp errors)."""

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import proxseg
from conftest import data, ycb_frame

# Two daemon threads recognising a small frame (learn0, every 4th pixel: ~0.1 s a call) over and
# over, so that one call or another ends while the interpreter exits; then the main thread
# exits (argv[3] "exit": sys.exit(5)) or waits in join() for a SIGINT ("join").
SCRIPT = r"""
import sys, threading, proxseg
full = proxseg.read_point_cloud(sys.argv[1])
frame = proxseg.Frame(full.xyz[::4, ::4].copy(), full.rgb[::4, ::4].copy())
db = proxseg.Database(sys.argv[2])
started = threading.Event()
def loop():
    while True:
        started.set()
        proxseg.recognize(frame, db)
workers = [threading.Thread(target=loop, daemon=True) for _ in range(2)]
for w in workers:
    w.start()
started.wait()
if sys.argv[3] == "exit":
    threading.Event().wait(float(sys.argv[4]))
    sys.exit(5)
# SIGINT to the main thread. Sent to the process from outside, 1 run in ~10 hung in join()
# without a traceback, before the fix as after: delivered to another thread, it seems, which
# does not wake the main thread's wait (not proxseg's to fix; not what this test is about).
import signal
threading.Timer(float(sys.argv[4]), signal.pthread_kill,
                (threading.main_thread().ident, signal.SIGINT)).start()
workers[0].join()
"""

# Runs of each kind: before the fix 7 of these 8 runs aborted (16 of 16 with the parent's kill).
RUNS = 4


def run_script(ycb_db, how: str, delay: float) -> subprocess.CompletedProcess:
    child = subprocess.Popen(
        [sys.executable, "-c", SCRIPT, str(data("mosd/learn/learn0.pcd")), str(ycb_db), how,
         str(delay)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out, err = child.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        child.kill()
        out, err = child.communicate()
        err += "\n(hung: killed after 30 s)"
    return subprocess.CompletedProcess(child.args, child.returncode, out, err)


def assert_no_abort(r: subprocess.CompletedProcess) -> None:
    for bad in ("terminate", "libgomp", "Fatal Python error", "Aborted"):
        assert bad not in r.stderr, f"exit {r.returncode}:\n{r.stderr}"


@pytest.mark.parametrize("run", range(RUNS))
def test_sys_exit_while_a_daemon_thread_recognises(ycb_db, run):
    r = run_script(ycb_db, "exit", 0.15 + 0.1 * run)
    assert_no_abort(r)
    assert r.returncode == 5, r.stderr


@pytest.mark.parametrize("run", range(RUNS))
def test_ctrl_c_in_join_while_a_daemon_thread_recognises(ycb_db, run):
    r = run_script(ycb_db, "join", 0.15 + 0.1 * run)
    assert_no_abort(r)
    # The KeyboardInterrupt's path: its traceback, and death by SIGINT (the shell's 130).
    assert r.returncode in (-signal.SIGINT, 130), f"exit {r.returncode}:\n{r.stderr}"
    assert "KeyboardInterrupt" in r.stderr, r.stderr


def test_a_call_begun_after_the_exit_handler_is_refused(tmp_path):
    # An atexit handler registered before the import runs after proxseg's: its call is refused
    # at once, with SystemExit (a thread ends on it quietly), and the process exits as asked.
    script = ("import atexit, sys\n"
              "def late():\n"
              "    try:\n"
              "        proxseg.segment([[0.0, 0.0, 1.0]] * 100)\n"
              "    except SystemExit as e:\n"
              "        print('refused:', e, flush=True)\n"
              "atexit.register(late)\n"
              "import proxseg\n"
              "sys.exit(3)\n")
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert r.returncode == 3, r.stderr
    assert r.stdout == "refused: proxseg: not started: the interpreter is exiting\n", r.stderr


def test_ctrl_c_stops_a_call_on_the_main_thread(ycb_db):
    # Without a thread: SIGINT while the main thread is in recognize() raises KeyboardInterrupt
    # from the call within a stop point or two, not when the call would have ended; then the
    # same call answers as before (nothing left half-done).
    f = ycb_frame(1)  # ~1 s: segmentation, then the candidates described and aligned
    frame = proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"])
    db = proxseg.Database(ycb_db)
    start = time.monotonic()
    whole = proxseg.recognize(frame, db)
    took = time.monotonic() - start
    timer = threading.Timer(took / 4, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        proxseg.recognize(frame, db)
    stopped = time.monotonic() - start
    timer.join()
    assert stopped < took * 0.75, f"stopped after {stopped:.3f} s of a {took:.3f} s call"
    again = proxseg.recognize(frame, db)
    assert again.names == whole.names and np.array_equal(again.object_ids, whole.object_ids)
