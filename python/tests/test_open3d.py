"""Open3D point clouds (legacy and tensor) in, labels that colour them out."""

import numpy as np
import pytest

import proxseg
from conftest import data

o3d = pytest.importorskip("open3d")


def test_legacy_and_tensor_clouds_segment_like_the_frame():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn5.pcd"))
    xyz = frame.xyz.reshape(-1, 3)
    keep = np.isfinite(xyz).all(axis=1)
    pts, rgb = xyz[keep], frame.rgb.reshape(-1, 3)[keep]
    legacy = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts.astype(np.float64)))
    legacy.colors = o3d.utility.Vector3dVector(rgb / 255.0)
    tensor = o3d.t.geometry.PointCloud(o3d.core.Tensor(pts))
    tensor.point.colors = o3d.core.Tensor(rgb)
    reference = proxseg.segment(pts, rgb=rgb)
    for cloud in (legacy, tensor):
        r = proxseg.segment(cloud)
        assert r.labels.shape == (len(pts),)
        assert np.array_equal(r.labels, reference.labels)
    # the labels colour the cloud point for point
    legacy.colors = o3d.utility.Vector3dVector(proxseg.label_colours(reference.labels))
    assert len(legacy.colors) == len(pts)


def test_colourless_open3d_cloud():
    model = o3d.io.read_point_cloud(str(data("pcl/milk.pcd")))
    model.colors = o3d.utility.Vector3dVector()
    frame = proxseg.as_frame(model)
    assert not frame.coloured and len(frame) == len(model.points)
    tensor = o3d.t.geometry.PointCloud(o3d.core.Tensor(np.asarray(model.points, np.float32)))
    assert not proxseg.as_frame(tensor).coloured


def test_other_open3d_geometry_is_refused():
    with pytest.raises(TypeError, match="expected an Open3D PointCloud or RGBDImage"):
        proxseg.as_frame(o3d.geometry.TriangleMesh())
