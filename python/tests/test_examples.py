"""The Python examples (examples/python/) run on real data and write what they say."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

import proxseg
from conftest import YCB_OBJECTS, data, scene_folder, ycb_frame

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "python"


def run(script, *args):
    r = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)],
                       capture_output=True, text=True)
    return r


def test_segment_pcd_writes_a_picture_and_lists_the_candidates(tmp_path):
    png = tmp_path / "candidates.png"
    r = run("segment_pcd.py", data("mosd/learn/learn7.pcd"), "-o", png)
    assert r.returncode == 0, r.stderr
    expected = proxseg.segment(proxseg.read_point_cloud(data("mosd/learn/learn7.pcd")))
    assert f"{len(expected.candidates)} candidates" in r.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10000
    bad = run("segment_pcd.py", tmp_path / "none.pcd")
    assert bad.returncode == 1 and "none.pcd: file not found" in bad.stderr


def test_recognize_scene_builds_a_database_and_names_the_objects(tmp_path):
    f = ycb_frame(4)
    models = [data(f"ycbv/models/{n}/points.xyz") for n in YCB_OBJECTS]
    ids = tmp_path / "ids.npy"
    r = run("recognize_scene.py", "--db", tmp_path / "db", "--models", *models, "--color",
            f["color"], "--depth", f["depth"], "--meta", f["meta"], "-o", ids)
    assert r.returncode == 0, r.stderr
    assert "009_gelatin_box" in r.stdout and "pose (camera <- model)" in r.stdout
    assert proxseg.Database(tmp_path / "db").objects == list(YCB_OBJECTS)
    assert np.load(ids).shape == (480, 640)


def test_segment_folder_segments_every_scene_with_a_bar(tmp_path):
    folder = scene_folder(tmp_path / "scenes", (0, 1, 2))
    out = tmp_path / "out"
    r = run("segment_folder.py", folder, "-o", out, "--threads", "2")
    assert r.returncode == 1  # the broken scene
    summary = json.loads((out / "summary.json").read_text())
    rows = {row["scene"]: row for row in summary["scenes"]}
    assert set(rows) == {"broken.pcd", "learn0.pcd", "learn1.pcd", "learn2.pcd"}
    assert "error" in rows["broken.pcd"] and "broken.pcd" in r.stderr
    assert "4/4" in r.stderr or "100%" in r.stderr  # the progress bar
    labels = np.load(out / "learn1.npz")["labels"]
    expected = proxseg.segment(proxseg.read_point_cloud(data("mosd/learn/learn1.pcd")))
    assert np.array_equal(labels, expected.labels)
    assert rows["learn1.pcd"]["candidates"] == len(expected.candidates)
