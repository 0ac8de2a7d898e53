"""Bad input raises the documented exceptions, with the C++ library's messages: OSError for files
that cannot be read or written, ValueError for bad content or values, TypeError for arguments of
the wrong kind; never a crash."""

import os

import numpy as np
import pytest

import proxseg
from conftest import data


def test_missing_and_unreadable_files_raise_oserror(tmp_path):
    # The subclass of OSError that the errno names (FileError's error).
    with pytest.raises(FileNotFoundError, match="nope.pcd: file not found"):
        proxseg.read_point_cloud(tmp_path / "nope.pcd")
    (tmp_path / "dir.pcd").mkdir()
    with pytest.raises(IsADirectoryError, match="dir.pcd: is a directory"):
        proxseg.read_point_cloud(tmp_path / "dir.pcd")
    with pytest.raises(FileNotFoundError, match="database.sqlite: does not exist"):
        proxseg.Database(tmp_path)
    with pytest.raises(FileNotFoundError, match="none: does not exist"):
        proxseg.Database(tmp_path / "none")
    (tmp_path / "file").write_text("x")
    with pytest.raises(OSError, match="file: is not a directory"):
        proxseg.Database(tmp_path / "file")
    with pytest.raises(OSError, match="file not found"):
        proxseg.read_rgbd(tmp_path / "nope-color.png", tmp_path / "d.png", meta=tmp_path / "m.json")
    with pytest.raises(OSError):
        proxseg.segment(tmp_path / "nope.ply")
    os.mkfifo(tmp_path / "fifo.pcd")  # refused at once, not read (a FIFO would block forever)
    with pytest.raises(OSError, match="fifo.pcd: is a FIFO"):
        proxseg.read_point_cloud(tmp_path / "fifo.pcd")
    (tmp_path / "zero.pcd").symlink_to("/dev/zero")
    with pytest.raises(OSError, match="zero.pcd: is a character device"):
        proxseg.segment(tmp_path / "zero.pcd")


def test_bad_file_content_raises_valueerror(tmp_path):
    bad = tmp_path / "bad.pcd"
    bad.write_text("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\n"
                   "HEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n4 five 6\n")
    with pytest.raises(ValueError, match=r"bad.pcd: line 11"):
        proxseg.read_point_cloud(bad)
    (tmp_path / "x.txt").write_text("1 2 3\n")
    with pytest.raises(ValueError, match="extension"):
        proxseg.read_point_cloud(tmp_path / "x.txt")
    with pytest.raises(ValueError, match="meta= or intrinsics="):
        proxseg.read_rgbd("a.png", "b.png")


@pytest.mark.parametrize("xyz, rgb, message", [
    (np.zeros((5, 2), np.float32), None, r"xyz: shape \(5, 2\)"),
    (np.zeros((5,), np.float32), None, r"xyz: shape \(5,\)"),
    (np.zeros((5, 3), np.complex64), None, "xyz: dtype complex64"),
    (np.zeros((5, 3), np.float32), np.full((5, 3), 2.0, np.float32),
     r"rgb: float colours must lie in \[0, 1\]"),
    (np.zeros((5, 3), np.float32), np.zeros((5, 3), np.int16), "rgb: dtype int16"),
    (np.zeros((5, 3), np.float32), np.zeros((4, 3), np.uint8), r"rgb: shape \(4, 3\)"),
    (np.zeros((2, 5, 3), np.float32), np.zeros((10, 3), np.uint8), r"expected \(2, 5, 3\)"),
])
def test_bad_arrays_raise_valueerror(xyz, rgb, message):
    with pytest.raises(ValueError, match=message):
        proxseg.Frame(xyz, rgb)


def test_bad_frames_and_parameters_raise_valueerror():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))
    with pytest.raises(ValueError, match="no valid points"):
        proxseg.segment(np.full((10, 3), np.nan, np.float32))
    with pytest.raises(ValueError, match=r"voxels.voxel_size: expected > 0 m, got 0"):
        proxseg.segment(frame, voxel_size=0)
    with pytest.raises(ValueError, match="bogus: no such parameter"):
        proxseg.segment(frame, bogus=1)
    with pytest.raises(ValueError, match="mrf.bogus: no such parameter"):
        proxseg.segment(frame, {"mrf": {"bogus": 1}})
    with pytest.raises(ValueError, match='mrf.method'):
        proxseg.segment(frame, mrf={"method": "annealing"})
    with pytest.raises(ValueError, match="preset: expected \"default\" or \"paper\""):
        proxseg.segment(frame, preset="fast")
    with pytest.raises(ValueError, match="more than max_memory_mib 40; refused before starting"):
        proxseg.segment(frame, max_memory_mib=40)
    with pytest.raises(ValueError, match="max_memory_mib"):
        proxseg.segment(frame, max_memory_mib=-1)
    with pytest.raises(ValueError, match="min_score"):
        proxseg.RecognitionParams(min_score=2)
    with pytest.raises(ValueError, match="a section"):
        proxseg.RecognitionParams(registration=5)


def test_bad_rgbd_arrays_raise_valueerror():
    depth = np.ones((4, 5), np.uint16)
    K = np.array([[500, 0, 2], [0, 500, 2], [0, 0, 1]], np.float64)
    with pytest.raises(ValueError, match=r"depth: shape \(20,\)"):
        proxseg.from_rgbd(None, depth.reshape(-1), K)
    with pytest.raises(ValueError, match=r"K: shape \(2, 2\)"):
        proxseg.from_rgbd(None, depth, np.eye(2))
    with pytest.raises(ValueError, match="fx, fy and depth_scale"):
        proxseg.from_rgbd(None, depth, K, depth_scale=0)
    with pytest.raises(ValueError, match=r"rgb: shape \(4, 4, 3\)"):
        proxseg.from_rgbd(np.zeros((4, 4, 3), np.uint8), depth, K)
    with pytest.raises(ValueError, match="depth: dtype int8"):
        proxseg.from_rgbd(None, depth.astype(np.int8), K)


def test_wrong_kinds_raise_typeerror(tmp_path):
    with pytest.raises(TypeError, match="expected a proxseg.Frame, a path"):
        proxseg.segment({"x": 1})
    with pytest.raises(TypeError, match="expected SegmentParams or a dict"):
        proxseg.segment(np.zeros((3, 3), np.float32), params=3)
    with pytest.raises(TypeError, match="db: int"):
        proxseg.recognize_object(np.zeros((3, 3), np.float32), 5)


def test_database_errors(tmp_path):
    empty = proxseg.Database(tmp_path / "new", create=True)
    with pytest.raises(ValueError, match="the database has no views"):
        proxseg.recognize_object(data("pcl/milk.pcd"), empty)
    with pytest.raises(ValueError, match="object name: expected a non-empty name"):
        empty.add_view("", np.zeros((3, 3), np.float32))
    with pytest.raises(ValueError, match="object name: expected a non-empty name"):
        empty.render("unknown", data("lmo/models/obj_000001.ply"))
    with pytest.raises(ValueError, match="viewpoint"):
        empty.add_view("a", np.zeros((3, 3), np.float32), viewpoint=(0, 0))
    with pytest.raises(ValueError, match="voxel_size: expected a positive size"):
        proxseg.Database(tmp_path / "other", create=True, voxel_size=-1)
    with pytest.raises(ValueError, match="units"):
        empty.render("a", data("lmo/models/obj_000001.ply"), units="cm")
    with pytest.raises(OSError, match="file not found"):
        empty.render("a", tmp_path / "none.ply")
    with pytest.raises(IndexError):
        empty.view(0)
    with pytest.raises(IndexError):
        empty.view(-1)
    assert len(empty) == 0 and not (tmp_path / "new" / "index.json").exists()
