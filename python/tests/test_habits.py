"""What Python users expect of the module: array-likes, Open3D RGB-D images with their grid,
concise errors, OSError subclasses, pickling, writers that match the CLI's, checked stubs."""

import json
import os
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import proxseg
from proxseg import _open3d
from conftest import data, run_cli


@pytest.fixture(scope="module")
def learn0():
    return proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))


def test_array_likes_and_float_colours_in_unit_range(learn0):
    lists = proxseg.Frame([[0.0, 0.0, 1.0], [0.1, 0.0, 1.0]], [[0.5, 0.25, 1.0], [0, 0, 0]])
    assert lists.rgb.tolist() == [[128, 64, 255], [0, 0, 0]]
    ints = proxseg.Frame(np.array([[0, 0, 1]], np.int64))
    assert ints.xyz.dtype == np.float32
    floats = proxseg.Frame(learn0.xyz, learn0.rgb / 255.0)  # Open3D's colours
    assert np.array_equal(floats.rgb, learn0.rgb)


def test_buffer_objects_are_frames_at_every_entry_point(learn0, ycb_db, tmp_path):
    # What Frame() takes (anything numpy.asarray takes: memoryview, array.array, ...) every entry
    # point that takes a cloud takes too; before, segment(memoryview) was refused (issue 54.9).
    xyz = np.ascontiguousarray(learn0.xyz[::4, ::4])
    rgb = np.ascontiguousarray(learn0.rgb[::4, ::4])
    frame = proxseg.Frame(xyz, rgb)
    assert np.array_equal(proxseg.Frame(memoryview(xyz), memoryview(rgb)).xyz, frame.xyz,
                          equal_nan=True)
    expected = proxseg.segment(frame)
    got = proxseg.segment(memoryview(xyz), rgb=memoryview(rgb))
    assert np.array_equal(got.labels, expected.labels)
    assert np.array_equal(proxseg.as_frame(memoryview(xyz)).xyz, frame.xyz, equal_nan=True)
    db = proxseg.Database(ycb_db)
    scene = proxseg.recognize(memoryview(xyz), db, rgb=memoryview(rgb))
    assert scene.names == proxseg.recognize(frame, db).names
    points = np.ascontiguousarray(xyz.reshape(-1, 3)[np.isfinite(xyz.reshape(-1, 3)).all(1)][:500])
    assert proxseg.recognize_object(memoryview(points), db).names == \
        proxseg.recognize_object(points, db).names
    copy = proxseg.Database(tmp_path / "db", create=True)
    assert copy.add_view("thing", memoryview(points))["points"] > 0
    # a buffer of what is no number (bytes: characters) is refused alike
    with pytest.raises(TypeError, match="bytes is not array-like"):
        proxseg.Frame(b"123")
    with pytest.raises(TypeError, match="bytes is not array-like"):
        proxseg.segment(b"123")


def test_errors_are_concise_whatever_the_input_size():
    big = [[0.0, 0.0, 1.0]] * 1_000_000  # ~14 MB as text
    for call in (lambda: proxseg.Frame(big, "no colours"), lambda: proxseg.Frame(object()),
                 lambda: proxseg.Frame(big[:5], np.zeros((4, 3), np.uint8))):
        with pytest.raises((TypeError, ValueError)) as e:
            call()
        assert len(str(e.value)) < 200, str(e.value)[:300]


def test_a_forbidden_file_raises_permissionerror(tmp_path):
    # The other subclasses of OSError: test_errors.py.
    locked = tmp_path / "locked.pcd"
    locked.write_bytes(Path(data("pcl/milk.pcd")).read_bytes())
    locked.chmod(0)
    try:
        if os.geteuid() != 0:  # root reads whatever the mode says
            with pytest.raises(PermissionError):
                proxseg.read_point_cloud(locked)
    finally:
        locked.chmod(0o600)


def test_frames_parameters_and_results_pickle(learn0):
    frame = pickle.loads(pickle.dumps(learn0))
    assert (frame.width, frame.height, frame.coloured) == (640, 480, True)
    assert np.array_equal(np.nan_to_num(frame.xyz), np.nan_to_num(learn0.xyz))
    assert np.array_equal(frame.rgb, learn0.rgb)
    result = proxseg.segment(learn0, threads=1)
    again = pickle.loads(pickle.dumps(result))
    assert np.array_equal(again.instances, result.instances)
    assert again.params == result.params and again.params.voxels.voxel_size == 0.02
    assert [c.id for c in again.candidates] == [c.id for c in result.candidates]
    params = pickle.loads(pickle.dumps(proxseg.SegmentParams(voxel_size=0.03)))
    assert params.voxels.voxel_size == 0.03
    labelled = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"), label_field="label")
    assert np.array_equal(pickle.loads(pickle.dumps(labelled)).label, labelled.label)


def test_save_writes_the_files_of_the_cli(learn0, tmp_path):
    result = proxseg.segment(learn0, threads=1)
    files = result.save(tmp_path / "py", outputs="all")
    assert [Path(f).name for f in files] == ["py.label.png", "py.instance.png", "py.pcd",
                                             "py.png", "py.json", "py.html"]
    run_cli("segment", data("mosd/learn/learn0.pcd"), "-o", tmp_path / "cli", "--outputs", "all",
            "--threads", "1")
    for ext in (".label.png", ".instance.png", ".pcd", ".png"):
        assert (tmp_path / f"py{ext}").read_bytes() == (tmp_path / f"cli{ext}").read_bytes(), ext

    def without_times(report):
        return {k: v for k, v in report.items() if "times" not in k and k != "input"}
    py = json.loads((tmp_path / "py.json").read_text())
    cli = json.loads((tmp_path / "cli.json").read_text())
    assert without_times(py) == without_times(cli)
    with pytest.raises(ValueError, match="--outputs|outputs"):
        result.save(tmp_path / "bad", outputs="pdf")


def test_write_point_cloud_round_trips(learn0, tmp_path):
    result = proxseg.segment(learn0, threads=1)
    path = tmp_path / "out.pcd"
    proxseg.write_point_cloud(path, learn0, fields={"instance": result.instances})
    back = proxseg.read_point_cloud(path, label_field="instance")
    assert back.shape == learn0.shape
    assert np.array_equal(back.rgb, learn0.rgb)
    assert np.array_equal(back.label, result.instances)
    with pytest.raises(ValueError, match=r"expected a \.pcd or \.ply path"):
        proxseg.write_point_cloud(tmp_path / "out.xyz", learn0)
    with pytest.raises(ValueError, match="one value per point"):
        proxseg.write_point_cloud(path, learn0, fields={"x": [1, 2]})


def test_candidate_indices_keep_the_old_name(learn0):
    c = proxseg.segment(learn0).candidates[0]
    assert c.points is c.indices and c.indices.dtype.kind in "iu"


def test_parameters_table_matches_the_cli_and_suggests_names():
    table = proxseg.parameters()
    cli = json.loads(run_cli("params", "--json").stdout)
    assert [r["key"] for r in table] == [r["key"] for r in cli["segmentation"]]
    assert [r["default"] for r in table] == [r["default"] for r in cli["segmentation"]]
    assert {r["key"] for r in proxseg.parameters("recognition")} >= {"min_score", "seed"}
    with pytest.raises(ValueError, match=r"did you mean voxel_size\?"):
        proxseg.SegmentParams(voxelsize=0.01)
    with pytest.raises(AttributeError, match=r"did you mean pairwise_weight\?"):
        proxseg.SegmentParams().mrf.pairwise


def test_open3d_rgbd_images_keep_the_grid(learn0):
    o3d = pytest.importorskip("open3d")
    depth = np.nan_to_num(learn0.xyz[..., 2]).astype(np.float32)
    K = [[525.0, 0, 319.5], [0, 525.0, 239.5], [0, 0, 1]]
    legacy = o3d.geometry.RGBDImage.create_from_color_and_depth(
        o3d.geometry.Image(np.ascontiguousarray(learn0.rgb)), o3d.geometry.Image(depth),
        depth_scale=1.0, depth_trunc=100.0, convert_rgb_to_intensity=False)
    intrinsic = o3d.camera.PinholeCameraIntrinsic(640, 480, 525.0, 525.0, 319.5, 239.5)
    tensor = o3d.t.geometry.RGBDImage(
        o3d.t.geometry.Image(np.ascontiguousarray(learn0.rgb)),
        o3d.t.geometry.Image(np.rint(depth * 1000).astype(np.uint16)))
    for frame in (proxseg.from_open3d(legacy, intrinsic), proxseg.from_open3d(tensor, K)):
        assert frame.organized and frame.shape == (480, 640)
        assert frame.coloured and frame.valid_count == learn0.valid_count
        assert proxseg.segment(frame).labels.shape == (480, 640)
    with pytest.raises(TypeError, match="needs its camera"):
        proxseg.as_frame(legacy)


def test_an_open3d_cloud_warns_once_that_the_grid_is_lost(learn0):
    pytest.importorskip("open3d")
    cloud = proxseg.to_open3d(learn0)
    assert len(cloud.points) == learn0.valid_count and cloud.has_colors()
    _open3d._warned_unorganized = False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        proxseg.as_frame(cloud)
        proxseg.as_frame(cloud)
    said = [w for w in caught if "no image grid" in str(w.message)]
    assert len(said) == 1 and said[0].filename == __file__
    coloured = proxseg.segment(learn0).to_open3d(by="instances")
    assert len(coloured.colors) == learn0.valid_count


def test_the_stubs_and_annotations_pass_mypy():
    pytest.importorskip("mypy")
    package = Path(proxseg.__file__).parent
    allowlist = Path(__file__).resolve().parents[1] / "stubtest-allowlist.txt"
    env = dict(os.environ, PYTHONPATH=str(package.parent))
    stubtest = subprocess.run([sys.executable, "-m", "mypy.stubtest", "proxseg._proxseg",
                               "--allowlist", str(allowlist)],
                              capture_output=True, text=True, cwd=package.parent, env=env)
    assert stubtest.returncode == 0, stubtest.stdout + stubtest.stderr
    typed = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", "/dev/null", "-p",
                            "proxseg"], capture_output=True, text=True, cwd=package.parent,
                           env=env)
    assert typed.returncode == 0, typed.stdout + typed.stderr


def test_render_refuses_a_mesh_implausible_for_its_units(tmp_path):
    db = proxseg.Database(tmp_path / "db", create=True)
    mesh = data("lmo/models/obj_000001.ply")  # millimetres
    with pytest.raises(ValueError, match=r"m across with units=m, too large for an object: its "
                                         r"coordinates look like millimetres; use units=mm"):
        db.render("ape", mesh, views=2)
    assert len(db.render("ape", mesh, views=2, units="mm")) == 2


def _without_run_details(report):
    """A report without what differs from run to run or by file name: times, the input's name,
    the files' names."""
    if isinstance(report, dict):
        return {k: _without_run_details(v) for k, v in report.items()
                if "times" not in k and k not in ("input", "file")}
    if isinstance(report, list):
        return [_without_run_details(v) for v in report]
    return report


def test_recognition_results_save_the_files_of_the_cli(tmp_path):
    from conftest import YCB_OBJECTS, ycb_frame
    db = tmp_path / "db"
    for name in YCB_OBJECTS:
        run_cli("db", "add", db, "--name", name, "--xyz", data(f"ycbv/models/{name}/points.xyz"))
    f = ycb_frame(4)
    frame = proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"])
    result = proxseg.recognize(frame, db, segment_params={"threads": 1}, threads=1)
    files = result.save(tmp_path / "py", outputs="all")
    assert sorted(Path(p).name for p in files) == ["py.html", "py.json", "py.object.png", "py.pcd",
                                                   "py.png"]
    run_cli("recognize", "--db", db, "--colour", f["color"], "--depth", f["depth"], "--meta",
            f["meta"], "-o", tmp_path / "cli", "--outputs", "all", "--threads", "1")
    for ext in (".pcd", ".png", ".object.png"):
        assert (tmp_path / f"py{ext}").read_bytes() == (tmp_path / f"cli{ext}").read_bytes(), ext
    py = json.loads((tmp_path / "py.json").read_text())
    cli = json.loads((tmp_path / "cli.json").read_text())
    assert _without_run_details(py) == _without_run_details(cli)
    assert "025_mug" in result.names
    cloud = result.to_open3d() if _has_open3d() else None
    assert cloud is None or len(cloud.points) == frame.valid_count
    again = pickle.loads(pickle.dumps(result))
    assert again.names == result.names
    with pytest.raises(ValueError, match="was pickled"):
        again.save(tmp_path / "again")
    one = proxseg.recognize_object(data("pcl/milk.pcd"), db)
    assert sorted(Path(p).name for p in one.save(tmp_path / "one")) == ["one.json", "one.png"]


def _has_open3d():
    try:
        import open3d  # noqa: F401
    except ImportError:
        return False
    return True


def test_colour_and_color_both_name_the_colour_image():
    f = {k: v for k, v in __import__("conftest").ycb_frame(1).items()}
    a = proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"])
    b = proxseg.read_rgbd(colour=f["color"], depth=f["depth"], meta=f["meta"])
    c = proxseg.read_rgbd(color=f["color"], depth=f["depth"], meta=f["meta"])
    assert np.array_equal(a.rgb, b.rgb) and np.array_equal(a.rgb, c.rgb)
    with pytest.raises(TypeError, match="colour or color, not both"):
        proxseg.read_rgbd(colour=f["color"], color=f["color"], depth=f["depth"], meta=f["meta"])
