"""proxseg.recognize / recognize_object / Database: equal to the CLI on the YCB-Video frames."""

import json

import numpy as np
import pytest

import proxseg
from conftest import YCB_OBJECTS, data, run_cli, ycb_frame


def without_times(report):
    """A recognition report entry without its wall times (the one thing that may differ)."""
    return {k: v for k, v in report.items() if k != "times_ms"}


@pytest.fixture(scope="module")
def db(ycb_db):
    return proxseg.Database(ycb_db)


@pytest.mark.parametrize("k", range(1, 11), ids=lambda k: f"{k:06d}")
def test_recognition_equals_the_cli(k, db, ycb_db, tmp_path):
    f = ycb_frame(k)
    prefix = tmp_path / "scene"
    r = run_cli("recognize", "--color", f["color"], "--depth", f["depth"], "--meta", f["meta"],
                "--db", ycb_db, "-o", prefix, "--json")
    report = json.loads(r.stdout)
    result = proxseg.recognize(proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"]), db)
    assert len(result.objects) == len(report["candidates"])
    for o, c in zip(result.objects, report["candidates"]):
        assert without_times(o.report) == without_times(c)
        assert (o.id, o.name, len(o.points)) == (c["id"], c["name"], c["points"])
        if "pose" in c:
            assert o.score == c["score"] and o.fitness == c["fitness"]
            assert np.array_equal(o.pose, np.array(c["pose"]))
    ids = proxseg.read_point_cloud(f"{prefix}.pcd", label_field="object").label
    assert result.object_ids.shape == (480, 640)
    assert result.object_ids.tobytes() == ids.tobytes()
    assert result.params["recognition"].to_dict() == report["parameters"]["recognition"]
    assert result.params["segmentation"].to_dict() == report["parameters"]["segmentation"]
    # the frame's three objects are among the names
    assert {"009_gelatin_box", "025_mug"} <= set(result.names)


def test_result_arrays_and_object_points(db):
    f = ycb_frame(1)
    result = proxseg.recognize(proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"]), db)
    n = len(result.objects)
    assert result.scores.shape == (n,) and result.poses.shape == (n, 4, 4)
    flat = result.object_ids.reshape(-1)
    for o in result.objects:
        assert np.all(flat[o.points] == o.id)
        if o.pose is not None:
            np.testing.assert_allclose(o.pose[:3, :3] @ o.pose[:3, :3].T, np.eye(3), atol=1e-9)
            assert o.pose[3].tolist() == [0, 0, 0, 1]
    assert np.count_nonzero(flat) == sum(len(o.points) for o in result.objects)
    assert result.segmentation is not None and result.segmentation.labels.shape == (480, 640)
    assert result.times_ms["segment"] > 0 and result.times_ms["recognize"] > 0


def test_recognize_object_equals_the_cli(tmp_path):
    db_dir = tmp_path / "milk-db"
    run_cli("db", "add", db_dir, "--name", "milk", data("pcl/milk.pcd"))
    r = run_cli("recognize", "--object", data("pcl/milk.pcd"), "--db", db_dir, "--json")
    report = json.loads(r.stdout)
    result = proxseg.recognize_object(data("pcl/milk.pcd"), db_dir)
    assert result.object_ids is None and result.segmentation is None
    (o,) = result.objects
    assert without_times(o.report) == without_times(report["candidates"][0])
    assert o.name == "milk" and o.id == 0 and o.known and o.fitness >= 0.9


def test_database_built_in_python_equals_the_cli_one(tmp_path, ycb_db):
    db = proxseg.Database(tmp_path / "db", create=True)
    assert len(db) == 0 and db.objects == []
    for name in YCB_OBJECTS:
        xyz = np.loadtxt(data(f"ycbv/models/{name}/points.xyz"), dtype=np.float64)
        db.add_view(name, xyz, viewpoint=None, source=str(data(f"ycbv/models/{name}/points.xyz")))
    assert db.objects == list(YCB_OBJECTS) and len(db) == 3
    cli = proxseg.Database(ycb_db)
    mine, theirs = db.info(), cli.info()
    assert mine.pop("dir") != theirs.pop("dir")
    for key in ("file", "file_bytes"):  # the path, and its WAL while a writer has it open
        mine.pop(key), theirs.pop(key)
    assert mine == theirs and mine["record_bytes"] > 100000
    for i in range(3):
        a, b = db.view(i), cli.view(i)
        assert a["object"] == b["object"] and np.array_equal(a["xyz"], b["xyz"])
    f = ycb_frame(3)
    frame = proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"])
    a, b = proxseg.recognize(frame, db), proxseg.recognize(frame, cli)
    assert a.names == b.names and np.array_equal(a.object_ids, b.object_ids)


def test_database_renders_views_of_a_mesh(tmp_path):
    db = proxseg.Database(tmp_path / "lm", create=True)
    views = db.render("duck", data("lmo/models/obj_000009.ply"), views=4, units="mm")
    assert len(views) == 4 and all(v["object"] == "duck" and v["coloured"] for v in views)
    assert len(proxseg.Database(tmp_path / "lm")) == 4
    # a rendered view names itself
    view = db.view(1)
    result = proxseg.recognize_object(view["xyz"] + np.array([0, 0, 0.6], np.float32), db,
                                      score="symmetric")
    assert result.objects[0].name == "duck"


def test_from_rgbd_equals_read_rgbd():
    PIL = pytest.importorskip("PIL.Image")
    f = ycb_frame(2)
    meta = json.loads(open(f["meta"]).read())
    scale = float(np.asarray(meta["factor_depth"]).reshape(-1)[0])
    color = np.asarray(PIL.open(f["color"]).convert("RGB"))
    depth = np.asarray(PIL.open(f["depth"])).astype(np.uint16)
    frame = proxseg.from_rgbd(color, depth, meta["intrinsic_matrix"], scale)
    ref = proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"])
    assert np.array_equal(frame.xyz, ref.xyz, equal_nan=True)
    assert np.array_equal(frame.rgb, ref.rgb)
    metres = proxseg.from_rgbd(None, depth.astype(np.float32) / scale,
                               meta["intrinsic_matrix"], 1.0)
    assert not metres.coloured
    np.testing.assert_allclose(metres.xyz, ref.xyz, rtol=1e-6, atol=1e-7)
