"""Several Python threads calling proxseg at once: the GIL is released and the answers equal
those of one thread."""

import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import proxseg
from conftest import data, mosd_learn, ycb_frame


def test_four_threads_segment_like_one():
    frames = [proxseg.read_point_cloud(p) for p in mosd_learn()[:8]]
    alone = [proxseg.segment(f) for f in frames]
    with ThreadPoolExecutor(max_workers=4) as pool:
        together = list(pool.map(proxseg.segment, frames + frames))
    for a, b in zip(alone + alone, together):
        assert np.array_equal(a.labels, b.labels) and np.array_equal(a.instances, b.instances)
    # one frame shared by four threads at once
    with ThreadPoolExecutor(max_workers=4) as pool:
        same = list(pool.map(lambda _: proxseg.segment(frames[0]), range(4)))
    assert all(np.array_equal(s.labels, alone[0].labels) for s in same)


def test_threads_recognize_with_one_database_like_one(ycb_db):
    db = proxseg.Database(ycb_db)
    frames = []
    for k in (1, 5, 9):
        f = ycb_frame(k)
        frames.append(proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"]))
    alone = [proxseg.recognize(f, db) for f in frames]
    with ThreadPoolExecutor(max_workers=3) as pool:
        together = list(pool.map(lambda f: proxseg.recognize(f, db), frames))
    for a, b in zip(alone, together):
        assert a.names == b.names and np.array_equal(a.object_ids, b.object_ids)
        assert np.array_equal(a.poses, b.poses, equal_nan=True)


def test_the_gil_is_released_while_segmenting():
    # While segment() runs on a thread, this thread keeps running Python: with the GIL held for
    # the whole call it would count only during the call's Python parts (a few ms of ~150 ms).
    frame = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))
    done = threading.Event()
    worker = threading.Thread(target=lambda: (proxseg.segment(frame, threads=1), done.set()))
    ticks = 0
    worker.start()
    while not done.is_set():
        ticks += 1
    worker.join()
    assert ticks > 100000, ticks
