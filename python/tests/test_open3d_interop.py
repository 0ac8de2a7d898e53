"""Open3D interop of issue 53: clouds read by Open3D keep their image grid (inferred or shape=),
grey RGB-D images warn, results, candidates, objects and boxes become Open3D geometries (legacy
and tensor, with instance/label/object attributes), and PLY files round-trip through proxseg's
and Open3D's readers."""

import warnings

import numpy as np
import pytest

import proxseg
from proxseg import _open3d
from conftest import data

o3d = pytest.importorskip("open3d")

LEARN17 = "mosd/learn/learn17.pcd"


@pytest.fixture(scope="module")
def learn17():
    path = data(LEARN17)
    return path, proxseg.segment(path, threads=1)


def _grid_warnings(caught):
    return [w for w in caught if "no image grid" in str(w.message)]


def test_an_open3d_read_of_an_organized_pcd_keeps_the_grid_and_the_labels(learn17):
    path, reference = learn17
    assert len(reference.candidates) == 2
    for cloud in (o3d.io.read_point_cloud(str(path)), o3d.t.io.read_point_cloud(str(path))):
        _open3d._warned_unorganized = False
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            frame = proxseg.from_open3d(cloud)
        assert not _grid_warnings(caught)
        assert frame.organized and frame.shape == (480, 640)
        r = proxseg.segment(frame, threads=1)
        assert np.array_equal(r.labels, reference.labels)
        assert np.array_equal(r.instances, reference.instances)
        assert len(r.candidates) == 2


def test_the_grid_is_inferred_only_for_points_laid_out_as_an_image():
    for k in (0, 17, 44):
        xyz = proxseg.read_point_cloud(data(f"mosd/learn/learn{k}.pcd")).xyz
        assert _open3d.image_grid(xyz.reshape(-1, 3)) == (480, 640)
        # every other row and column: a 320x240 image of the same scene
        assert _open3d.image_grid(np.ascontiguousarray(xyz[::2, ::2]).reshape(-1, 3)) == (240, 320)
        flat = xyz.reshape(-1, 3)
        shuffled = flat[np.random.default_rng(k).permutation(len(flat))]
        assert _open3d.image_grid(shuffled) is None
        by_x = flat[np.argsort(flat[:, 0] / flat[:, 2], kind="stable")]  # NaN last
        assert _open3d.image_grid(by_x) is None
        assert _open3d.image_grid(flat[:-1]) is None  # no sensor's size
        transposed = np.ascontiguousarray(xyz.transpose(1, 0, 2)).reshape(-1, 3)
        assert _open3d.image_grid(transposed) is None  # column-major


def test_a_cloud_open3d_projects_with_every_pixel_keeps_the_grid():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))
    rgbd = o3d.geometry.RGBDImage.create_from_color_and_depth(
        o3d.geometry.Image(np.ascontiguousarray(frame.rgb)),
        o3d.geometry.Image(np.nan_to_num(frame.xyz[..., 2]).astype(np.float32)),
        depth_scale=1.0, depth_trunc=100.0, convert_rgb_to_intensity=False)
    intrinsic = o3d.camera.PinholeCameraIntrinsic(640, 480, 525.0, 525.0, 319.5, 239.5)
    every = o3d.geometry.PointCloud.create_from_rgbd_image(rgbd, intrinsic,
                                                           project_valid_depth_only=False)
    organized = proxseg.from_open3d(every)
    assert organized.shape == (480, 640) and organized.valid_count == frame.valid_count
    valid = np.isfinite(frame.xyz).all(axis=2)  # Open3D's colour of an invalid pixel is 0
    assert np.array_equal(organized.rgb[valid], frame.rgb[valid])


def test_shape_wins_and_a_cloud_without_a_grid_warns_how_to_keep_it():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn5.pcd"))
    flat = frame.xyz.reshape(-1, 3)
    rgb = frame.rgb.reshape(-1, 3)
    order = np.random.default_rng(5).permutation(len(flat))
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(flat[order].astype(np.float64)))
    cloud.colors = o3d.utility.Vector3dVector(rgb[order] / 255.0)
    forced = proxseg.from_open3d(cloud, shape=(480, 640))  # shape= always wins
    assert forced.shape == (480, 640)
    assert np.array_equal(forced.xyz.reshape(-1, 3), flat[order], equal_nan=True)
    assert np.array_equal(forced.rgb.reshape(-1, 3), rgb[order])
    with pytest.raises(ValueError, match=r"shape: \(100, 100\) holds 10000 points but the cloud "
                                         r"has 307200"):
        proxseg.from_open3d(cloud, shape=(100, 100))
    with pytest.raises(TypeError, match="expected \\(H, W\\)"):
        proxseg.from_open3d(cloud, shape="480x640")
    _open3d._warned_unorganized = False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        loose = proxseg.from_open3d(cloud)
        proxseg.as_frame(cloud)
    said = _grid_warnings(caught)
    assert not loose.organized and loose.shape == (307200,)
    assert len(said) == 1 and said[0].filename == __file__
    text = str(said[0].message)
    assert "shape=(H, W)" in text and "times the CPU time of the organized frame" in text
    assert "about 3x" not in text


def test_a_grey_rgbd_image_warns_once_with_the_fix():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))
    colour = o3d.geometry.Image(np.ascontiguousarray(frame.rgb))
    depth = o3d.geometry.Image(np.nan_to_num(frame.xyz[..., 2]).astype(np.float32))
    intrinsic = o3d.camera.PinholeCameraIntrinsic(640, 480, 525.0, 525.0, 319.5, 239.5)
    grey = o3d.geometry.RGBDImage.create_from_color_and_depth(colour, depth, depth_scale=1.0,
                                                              depth_trunc=100.0)
    rgb = o3d.geometry.RGBDImage.create_from_color_and_depth(
        colour, depth, depth_scale=1.0, depth_trunc=100.0, convert_rgb_to_intensity=False)
    _open3d._warned_grey = False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        a = proxseg.from_open3d(grey, intrinsic)
        proxseg.from_open3d(grey, intrinsic)
        b = proxseg.from_open3d(rgb, intrinsic)
    said = [w for w in caught if "grey" in str(w.message)]
    assert len(said) == 1 and said[0].filename == __file__
    assert "convert_rgb_to_intensity=False" in str(said[0].message)
    assert a.coloured and np.all(a.rgb[..., 0] == a.rgb[..., 1])
    assert np.array_equal(b.rgb, frame.rgb)


def _column(cloud, name):
    t = cloud.point[name]
    assert t.dtype == o3d.core.Dtype.Int32 and tuple(t.shape)[1:] == (1,)
    return t.numpy()[:, 0]


def test_results_frames_and_candidates_become_legacy_and_tensor_clouds(learn17):
    path, result = learn17
    frame = result.frame
    valid = np.isfinite(frame.xyz.reshape(-1, 3)).all(axis=1)
    legacy = proxseg.to_open3d(result)  # the module function takes a result
    assert isinstance(legacy, o3d.geometry.PointCloud) and len(legacy.points) == valid.sum()
    by_label = proxseg.label_colours(result.instances).reshape(-1, 3)[valid]
    assert np.allclose(np.asarray(legacy.colors), by_label)
    scene = np.asarray(proxseg.to_open3d(result, by="colors").colors)
    assert np.array_equal(scene, np.asarray(result.to_open3d(by="colours").colors))
    assert np.allclose(scene, frame.rgb.reshape(-1, 3)[valid] / 255.0)
    with pytest.raises(ValueError, match="expected 'instances', 'labels', 'colours' or 'colors'"):
        result.to_open3d(by="objects")
    tensor = proxseg.to_open3d(result, tensor=True)
    assert isinstance(tensor, o3d.t.geometry.PointCloud)
    assert np.array_equal(tensor.point.positions.numpy(), frame.xyz.reshape(-1, 3)[valid])
    assert np.array_equal(_column(tensor, "instance"), result.instances.reshape(-1)[valid])
    assert np.array_equal(_column(tensor, "label"), result.labels.reshape(-1)[valid])
    assert tensor.point.colors.dtype == o3d.core.Dtype.Float32
    # a frame, with colours under either spelling
    red = np.zeros(frame.shape + (3,))
    red[..., 0] = 1.0
    assert np.array_equal(np.asarray(proxseg.to_open3d(frame, colors=red).colors)[:, 0],
                          np.ones(valid.sum()))
    assert proxseg.label_colors is proxseg.label_colours and frame.colored == frame.coloured
    with pytest.raises(TypeError, match="give colour or color, not both"):
        proxseg.to_open3d(frame, colours=red, colors=red)
    with pytest.raises(TypeError, match="expected a proxseg Frame, SegmentResult"):
        proxseg.to_open3d("scene.pcd")
    # each candidate its own cloud
    for c in result.candidates:
        own = proxseg.to_open3d(c, tensor=True)
        assert len(own.point.positions) == len(c.indices)
        assert set(_column(own, "instance")) == {c.id}
        assert len(c.to_open3d().points) == len(c.indices)


def test_boxes_become_oriented_bounding_boxes(learn17):
    _, result = learn17
    for c in result.candidates + result.background:
        box = c.box.to_open3d()
        assert isinstance(box, o3d.geometry.OrientedBoundingBox)
        assert c.box.center is c.box.centre
        assert np.allclose(box.center, c.box.centre) and np.allclose(box.R, c.box.axes)
        assert np.allclose(box.extent, c.box.extent)
        assert proxseg.to_open3d(c.box).volume() == pytest.approx(np.prod(c.box.extent))
        # the box holds its points (those on its faces within rounding)
        grown = o3d.geometry.OrientedBoundingBox(box.center, box.R, box.extent + 1e-4)
        points = c.to_open3d().points
        assert len(grown.get_point_indices_within_bounding_box(points)) == len(points)
    with pytest.raises(TypeError, match="OrientedBoundingBox"):
        proxseg.to_open3d(result.candidates[0].box, tensor=True)


def test_recognition_results_carry_object_attributes(ycb_db):
    from conftest import ycb_frame
    f = ycb_frame(4)
    frame = proxseg.read_rgbd(f["color"], f["depth"], meta=f["meta"])
    result = proxseg.recognize(frame, ycb_db)
    valid = np.isfinite(frame.xyz.reshape(-1, 3)).all(axis=1)
    cloud = proxseg.to_open3d(result, tensor=True)
    objects = _column(cloud, "object")
    assert np.array_equal(objects, result.object_ids.reshape(-1)[valid])
    assert np.array_equal(_column(cloud, "instance"),
                          result.segmentation.instances.reshape(-1)[valid])
    names = np.array(result.object_names)
    assert names[0] == "" and "025_mug" in set(names[objects])
    for o in result.objects:
        assert names[o.id] == o.name and o.color == o.colour
        own = o.to_open3d(tensor=True)
        assert set(_column(own, "object")) == {o.id} and len(own.point.positions) == len(o.indices)
    assert len(result.to_open3d(by="labels").points) == valid.sum()


def test_ply_round_trips_through_proxseg_and_open3d(learn17, tmp_path):
    path, result = learn17
    frame = result.frame
    flat, rgb = frame.xyz.reshape(-1, 3), frame.rgb.reshape(-1, 3)
    valid = np.isfinite(flat).all(axis=1)
    ply = tmp_path / "scene.ply"
    proxseg.write_point_cloud(ply, frame, fields={"instance": result.instances,
                                                  "label": result.labels})
    back = proxseg.read_point_cloud(ply, label_field="instance")
    assert back.shape == (valid.sum(),)
    assert np.array_equal(back.label, result.instances.reshape(-1)[valid])
    assert np.array_equal(back.xyz, flat[valid]) and np.array_equal(back.rgb, rgb[valid])
    legacy = o3d.io.read_point_cloud(str(ply))
    assert np.array_equal(np.asarray(legacy.points), flat[valid].astype(np.float64))
    assert np.allclose(np.asarray(legacy.colors), rgb[valid] / 255.0)
    tensor = o3d.t.io.read_point_cloud(str(ply))
    assert np.array_equal(_column(tensor, "instance"), result.instances.reshape(-1)[valid])
    assert np.array_equal(_column(tensor, "label"), result.labels.reshape(-1)[valid])
    # every point, NaN kept: vertex i is the frame's point i
    every = tmp_path / "every.ply"
    proxseg.write_point_cloud(every, frame, fields={"instance": result.instances},
                              keep_invalid=True)
    again = proxseg.read_point_cloud(every)
    assert len(again) == len(flat) and again.valid_count == valid.sum()
    assert np.array_equal(again.xyz, flat, equal_nan=True)
    kept = o3d.t.io.read_point_cloud(str(every))
    assert len(kept.point.positions) == len(flat)
    assert np.array_equal(_column(kept, "instance"), result.instances.reshape(-1))
    with pytest.raises(ValueError, match="is used twice"):
        proxseg.write_point_cloud(tmp_path / "bad.ply", frame, fields={"red": result.labels})
    assert not (tmp_path / "bad.ply").exists()
