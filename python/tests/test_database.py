"""The model database shared by processes and threads (docs/database.md, "Sharing"): two CLI
writers and four CLI readers at once, a Python Database beside a CLI add, SIGKILL during an add,
a write refused for want of space, an add while threads recognise; an object name that is not
UTF-8, a database read without write access (issue 54)."""

import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import proxseg
from conftest import CLI, data, run_cli

DUCK = data("lmo/models/obj_000009.ply")


def cli(*args):
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)


def render(db, name, views=1):
    return run_cli("db", "render", db, "--name", name, DUCK, "--views", views, "--units", "mm")


def info(db):
    return json.loads(run_cli("db", "info", db, "--json").stdout)


def check(db):
    r = cli("db", "check", db, "--json")
    assert r.returncode == 0, r.stdout + r.stderr
    return json.loads(r.stdout)


def test_two_writers_and_four_readers_across_processes(tmp_path):
    db = tmp_path / "db"
    render(db, "seed", views=2)
    done = threading.Event()
    failures, counts = [], []

    def write(k):
        try:
            for i in range(4):
                render(db, f"w{k}-{i}")
        except AssertionError as e:
            failures.append(str(e))

    def read():
        while not done.is_set():
            r = cli("recognize", "--object", data("pcl/milk.pcd"), "--db", db, "--json")
            if r.returncode != 0:
                failures.append(r.stderr)
                continue
            report = json.loads(r.stdout)
            counts.append(report["database"]["views"])
            if report["database"]["damaged_views"]:
                failures.append(str(report["database"]["damaged_views"]))

    writers = [threading.Thread(target=write, args=(k,)) for k in range(2)]
    readers = [threading.Thread(target=read) for _ in range(4)]
    for t in writers + readers:
        t.start()
    for t in writers:
        t.join()
    done.set()
    for t in readers:
        t.join()
    assert failures == []
    assert len(counts) >= 4 and all(2 <= c <= 10 for c in counts)
    got = info(db)
    assert got["views"] == 10 and len(got["objects"]) == 9  # every add landed
    assert check(db)["whole"] == 10


def test_a_python_database_keeps_what_another_process_added(tmp_path):
    db_path = tmp_path / "db"
    render(db_path, "first")
    db = proxseg.Database(db_path)
    render(db_path, "from the cli")  # another process, after this one opened it
    xyz = np.asarray(db.view(0)["xyz"])
    db.add_view("from python", xyz + 0.001)
    assert proxseg.Database(db_path).objects == ["first", "from the cli", "from python"]
    assert db.objects == ["first", "from python"]  # its own snapshot, plus its own adds
    assert db.remove("first") == 1 and db.rename("from python", "renamed") == 1
    assert proxseg.Database(db_path).objects == ["from the cli", "renamed"]


def test_sigkill_during_an_add_leaves_the_database_whole(tmp_path):
    db = tmp_path / "db"
    render(db, "seed", views=2)
    before = 2
    for delay in (0.15, 0.4, 0.8, 1.2, 1.8):
        p = subprocess.Popen([CLI, "db", "render", db, "--name", f"k{delay}", DUCK, "--views", "32",
                              "--units", "mm"], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
        time.sleep(delay)
        p.kill()
        p.wait()
        state = check(db)
        assert state["damaged"] == [] and state["whole"] == state["views"] >= before
        before = state["views"]
    assert proxseg.Database(db).view(0)["object"] == "seed"


def test_a_full_disk_leaves_the_database_as_it_was(tmp_path):
    db = tmp_path / "db"
    render(db, "seed", views=2)
    # A limit on file size stands for a full disk: the first add's write-ahead log grows past
    # 64 KB and the write fails (SIGXFSZ ignored, so the write returns EFBIG).
    r = subprocess.run(["bash", "-c", "trap '' XFSZ; ulimit -f 64; "
                        f"exec {CLI} db render {db} --name big {DUCK} --views 8 --units mm"],
                       capture_output=True, text=True)
    assert r.returncode == 1, r.stderr
    assert "database.sqlite" in r.stderr and "what was there is kept" in r.stderr, r.stderr
    assert r.stderr.count("\n") == 1, r.stderr
    state = check(db)
    assert state["views"] == 2 and state["whole"] == 2
    assert info(db)["objects"][0]["name"] == "seed" and len(info(db)["objects"]) == 1


def test_an_add_does_not_wait_behind_recognitions(tmp_path):
    db_path = tmp_path / "db"
    render(db_path, "duck", views=4)
    db = proxseg.Database(db_path)
    views = [np.asarray(db.view(i)["xyz"]) for i in range(4)]
    start = time.monotonic()
    db.add_view("alone", views[0])
    alone = time.monotonic() - start
    done = threading.Event()
    recognitions = []

    def recognize(k):
        while not done.is_set():
            recognitions.append(proxseg.recognize_object(views[k], db).objects[0].name)

    threads = [threading.Thread(target=recognize, args=(k,)) for k in range(3)]
    for t in threads:
        t.start()
    time.sleep(0.5)
    slowest = 0.0
    for i in range(3):
        start = time.monotonic()
        db.add_view(f"busy {i}", views[i + 1])
        slowest = max(slowest, time.monotonic() - start)
    done.set()
    for t in threads:
        t.join()
    assert len(recognitions) >= 3 and set(recognitions) <= {"duck", "alone", "busy 0", "busy 1",
                                                            "busy 2"}
    assert slowest < 3 * alone + 1.0, (slowest, alone)
    assert len(proxseg.Database(db_path)) == 8


def test_a_database_holding_an_object_name_not_utf8_still_opens(tmp_path):
    # Issue 54: a name an older version took (here put in by sqlite3) is shown as mug\xFF.
    import sqlite3

    db = tmp_path / "db"
    run_cli("db", "add", db, "--name", "mug", "--xyz", data("ycbv/models/025_mug/points.xyz"))
    with sqlite3.connect(db / "database.sqlite") as c:
        c.execute("UPDATE views SET object = CAST(X'6D7567FF' AS TEXT)")
    c.close()
    assert proxseg.Database(db).objects == ["mug\\xFF"]
    assert [o["name"] for o in info(db)["objects"]] == ["mug\\xFF"]
    # and a new name that is not UTF-8 is refused
    r = subprocess.run([CLI, "db", "add", str(db), "--name", b"mug\xfe", "--xyz",
                        str(data("ycbv/models/025_mug/points.xyz"))], capture_output=True)
    assert r.returncode == 1 and b"UTF-8" in r.stderr, r.stderr


MILK = data("pcl/milk.pcd")


def test_a_read_only_database_is_read_and_nothing_is_made_beside_it(tmp_path):
    # Issue 54: a file and folder nobody may write (root may, but they are meant to stay as they
    # are) are read as immutable: no -wal, -shm or -journal; writing is refused with the file.
    # The folder's name holds the characters a file: URI gives a meaning to.
    db = tmp_path / "a?b#c%20d" / "db"
    run_cli("db", "add", db, "--name", "milk", MILK)
    (db / "database.sqlite").chmod(0o444)
    db.chmod(0o555)
    try:
        before = sorted(os.listdir(db))
        d = proxseg.Database(db)
        assert d.objects == ["milk"] and d.info()["views"] == 1
        assert d.check()["whole"] == 1 and len(d.view(0)["xyz"]) > 0
        try:
            d.add_view("other", np.asarray(d.view(0)["xyz"]))
            raise AssertionError("an add into a read-only database was accepted")
        except OSError as e:
            assert "database.sqlite" in str(e) and "0444" in str(e), e
        del d
        assert sorted(os.listdir(db)) == before
    finally:
        db.chmod(0o755)
        (db / "database.sqlite").chmod(0o644)
    # Writable again: read and written in place, whatever its folder's name.
    d = proxseg.Database(db)
    d.add_view("other", np.asarray(d.view(0)["xyz"]))
    assert proxseg.Database(db).objects == ["milk", "other"]


HOLD = """
import sqlite3, sys, time
c = sqlite3.connect(sys.argv[1], isolation_level=None)
c.execute("BEGIN")
c.execute("SELECT count(*) FROM views").fetchall()
print("holding", flush=True)
time.sleep(60)
"""


def test_a_wal_holding_changes_is_read_or_refused_never_ignored(tmp_path):
    # A process killed while it read the database kept the writer's checkpoint from folding
    # the add in: database.sqlite-wal holds it. A reader that may not write reads it through the
    # -shm; without the -shm it says so, naming the -wal, rather than read the file without it.
    db = tmp_path / "db"
    run_cli("db", "add", db, "--name", "milk", MILK)
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(db / "database.sqlite")],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "holding\n"
        run_cli("db", "add", db, "--name", "second", MILK)
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    assert (db / "database.sqlite-wal").stat().st_size > 0
    (db / "database.sqlite").chmod(0o444)
    db.chmod(0o555)
    try:
        assert proxseg.Database(db).objects == ["milk", "second"]
        assert [o["name"] for o in info(db)["objects"]] == ["milk", "second"]
        db.chmod(0o755)
        os.remove(db / "database.sqlite-shm")
        db.chmod(0o555)
        r = cli("db", "info", db)
        assert r.returncode == 1, r.stdout
        assert "database.sqlite-wal holds changes" in r.stderr, r.stderr
        assert "proxseg db info" in r.stderr, r.stderr
    finally:
        db.chmod(0o755)
        (db / "database.sqlite").chmod(0o644)
    assert info(db)["views"] == 2  # a process that may write folds the -wal in
    assert sorted(os.listdir(db)) == ["database.sqlite"]
