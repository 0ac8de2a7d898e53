"""proxseg.segment: equal to the CLI on real scenes, shapes, parameters, frames from numpy."""

import json

import numpy as np
import pytest

import proxseg
from conftest import data, mosd_learn, run_cli


@pytest.fixture(scope="module")
def cli_learn(tmp_path_factory):
    """`proxseg segment --batch` over the 45 mOSD learn scenes: one CLI process, its outputs."""
    out = tmp_path_factory.mktemp("learn")
    run_cli("segment", "--batch", data("mosd/learn"), "-o", out)
    return out


@pytest.mark.parametrize("scene", mosd_learn(), ids=lambda p: p.stem)
def test_labels_equal_the_cli_byte_for_byte(scene, cli_learn):
    result = proxseg.segment(proxseg.read_point_cloud(scene))
    labels = proxseg.read_point_cloud(cli_learn / f"{scene.stem}.pcd", label_field="label").label
    instances = proxseg.read_point_cloud(cli_learn / f"{scene.stem}.pcd",
                                         label_field="instance").label
    assert result.labels.shape == (480, 640) and result.labels.dtype == np.uint32
    assert result.labels.tobytes() == labels.tobytes()
    assert result.instances.tobytes() == instances.tobytes()
    report = json.loads((cli_learn / f"{scene.stem}.json").read_text())
    assert result.k == report["k"]
    assert result.report["candidates"] == report["candidates"]
    assert result.params.to_dict() == report["parameters"]


def test_result_describes_the_candidates():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))
    r = proxseg.segment(frame)
    # The default's labels are its image-grid surfaces; the paper's labels on request.
    assert r.k == 0 and r.params.paper_labels is False
    paper = proxseg.segment(frame, paper_labels=True)
    assert paper.labels.max() <= paper.k and paper.labels.min() == 0 and paper.k >= 2
    assert np.array_equal(paper.instances, r.instances)
    assert set(paper.times_ms) >= {"voxels", "features", "mrf", "selection", "total"}
    assert len(r.candidates) >= 1 and len(r.background) >= 1
    xyz = frame.xyz.reshape(-1, 3)
    for c in r.candidates + r.background:
        assert c.points.dtype == np.int32 and np.all(np.diff(c.points) > 0)
        assert np.all(r.instances.reshape(-1)[c.points] == c.id)
        np.testing.assert_allclose(c.centroid, xyz[c.points].astype(np.float64).mean(axis=0),
                                   atol=1e-5)
        np.testing.assert_allclose(c.box.axes.T @ c.box.axes, np.eye(3), atol=1e-9)
        assert np.all(c.box.extent > 0)
    assert not any(c.background for c in r.candidates)
    assert set(r.times_ms) >= {"image_surfaces", "selection", "total"}
    assert r.report["proxseg"]["version"] == proxseg.__version__


def test_frame_from_numpy_equals_the_file():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn3.pcd"))
    copy = proxseg.Frame(frame.xyz.copy(), frame.rgb.copy())
    assert copy.organized and copy.shape == (480, 640)
    a, b = proxseg.segment(frame), proxseg.segment(copy)
    assert np.array_equal(a.labels, b.labels) and np.array_equal(a.instances, b.instances)
    # float64 points, and numpy arrays passed straight to segment() with rgb= beside them
    c = proxseg.segment(frame.xyz.astype(np.float64), rgb=frame.rgb)
    assert np.array_equal(a.labels, c.labels)


def test_views_share_the_frame_storage():
    frame = proxseg.Frame(np.zeros((4, 3), np.float32), np.zeros((4, 3), np.uint8))
    frame.xyz[2] = (1, 2, 3)
    assert frame.xyz[2].tolist() == [1, 2, 3]
    assert not frame.xyz.flags.owndata and frame.xyz.base is not None
    assert frame.rgb.dtype == np.uint8 and frame.rgb.shape == (4, 3)


def test_unorganized_results_have_one_value_per_point():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))
    xyz = frame.xyz.reshape(-1, 3)
    keep = np.isfinite(xyz).all(axis=1)
    r = proxseg.segment(xyz[keep], rgb=frame.rgb.reshape(-1, 3)[keep])
    assert r.labels.shape == (int(keep.sum()),) and r.instances.shape == r.labels.shape
    assert r.report["input"]["organized"] is False
    assert (r.labels > 0).all()


def test_parameters_by_preset_dict_object_and_name():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))
    paper = proxseg.SegmentParams(preset="paper")
    assert paper.mrf.pairwise_weight == 0.275 and paper.voxels.voxel_size == 0.02
    p = proxseg.SegmentParams(voxel_size=0.03, mrf={"enabled": False})
    assert p.voxels.voxel_size == 0.03 and p.mrf.enabled is False
    p.mrf.enabled = True
    assert p.mrf.enabled is True
    with pytest.raises(AttributeError):
        p.voxels.voxel_sise = 1
    by_object = proxseg.segment(frame, proxseg.SegmentParams(preset="paper", threads=1))
    by_dict = proxseg.segment(frame, {"threads": 1}, preset="paper")
    by_name = proxseg.segment(frame, preset="paper", threads=1)
    assert by_object.params == by_dict.params == by_name.params
    assert by_object.params.threads == 1 and by_object.params.mrf.pairwise_weight == 0.275
    assert np.array_equal(by_object.labels, by_name.labels)
    off = proxseg.segment(frame, mrf={"enabled": False})
    assert off.params.mrf.enabled is False and np.array_equal(off.labels, off.labels_kmeans)


def test_selection_sections_nest_and_old_names_warn():
    p = proxseg.SegmentParams(selection={"normal_step": 5, "occlusion": {"window": 60}})
    assert p.selection.image.normal_step == 5 and p.selection.occlusion.window == 60
    assert p.to_dict()["selection"]["containers"]["enabled"] is True
    with pytest.warns(DeprecationWarning, match="selection.join_occluded is now "
                                                "selection.occlusion.enabled"):
        old = proxseg.SegmentParams(selection={"join_occluded": False})
    assert old.selection.occlusion.enabled is False
    with pytest.warns(DeprecationWarning, match="image_normal_step is now"):
        old = proxseg.SegmentParams(image_normal_step=3)
    assert old.selection.image.normal_step == 3
    with pytest.warns(DeprecationWarning, match="selection.container_min_depth is now"):
        old.selection.container_min_depth = 0.05
    assert old.selection.containers.min_depth == 0.05
    with pytest.raises(ValueError, match="in several sections"):
        proxseg.SegmentParams(enabled=False)
    with pytest.raises(AttributeError, match="no such parameter"):
        old.selection.image_normal_stepp = 1
    rows = {r["key"]: r for r in proxseg.parameters()}
    assert rows["selection.image.normal_step"]["old_key"] == "selection.image_normal_step"


def test_colourless_clouds_run_without_colour_and_texture():
    frame = proxseg.read_point_cloud(data("mosd/learn/learn0.pcd"))
    grey = proxseg.Frame(frame.xyz.copy())
    assert not grey.coloured and grey.rgb is None
    r = proxseg.segment(grey)
    off = proxseg.segment(frame, features={"use_colour": False, "use_texture": False})
    assert np.array_equal(r.labels, off.labels)
    assert r.report["features"]["colour"] is False and r.report["features"]["texture"] is False
    assert "no colour" in r.report["features"]["note"]


def test_label_colours_colour_an_open3d_cloud():
    labels = np.array([[0, 1], [2, 1]], np.uint32)
    c = proxseg.label_colours(labels)
    assert c.shape == (2, 2, 3) and c.dtype == np.float64
    assert np.all(c[0, 0] == 0) and np.array_equal(c[0, 1], c[1, 1])
    assert not np.array_equal(c[0, 1], c[1, 0]) and np.all((c >= 0) & (c <= 1))
