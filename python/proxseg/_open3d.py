"""Open3D interop: frames from Open3D clouds and RGB-D images (keeping the image grid where there is
one), and Open3D clouds and boxes from frames, results, candidates and objects."""

from __future__ import annotations

import warnings
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

from ._frame import _caller_level, _one_colour, from_rgbd
from ._proxseg import Frame

# Image sizes (rows, columns) of common depth sensors, tried in this order when an Open3D cloud
# holds exactly rows x columns points: Kinect / Xtion / PrimeSense (VGA, QVGA), RealSense
# (1280x720, 848x480, 640x360, 1920x1080), Kinect v2 depth (512x424), Orbbec / Azure Kinect
# (640x400, 1280x800, 640x576, 1024x1024, 320x288) and QQVGA.
SENSOR_SIZES: Tuple[Tuple[int, int], ...] = (
    (480, 640), (240, 320), (720, 1280), (480, 848), (1080, 1920), (424, 512), (400, 640),
    (800, 1280), (360, 640), (576, 640), (1024, 1024), (288, 320), (120, 160))

# Of the finite neighbours along rows (columns), the share whose x/z (y/z) must increase for the
# points to be taken as a pinhole image grid: exact for a sensor's cloud (x/z = (u - cx) / fx),
# about one half for points in any other order.
_GRID_AGREEMENT = 0.99

# segment() of a cloud without its grid against the organized frame: the medians of two runs of
# `make bench-python` (bench/python_bench.py, "Open3D clouds against paths": 6 mOSD learn
# scenes, 2 busy cores): CPU 1457 ms against 37 ms (39x) and 1336 ms against 43 ms (31x); wall
# 32x and 16x.
_UNORGANIZED_SLOWDOWN = ("30 to 40 times the CPU time of the organized frame (measured: 1.3-1.5 s "
                         "against 0.04 s")

_warned_unorganized = False
_warned_grey = False


def _warn_unorganized_once(what: str, points: int) -> None:
    """Says once per process that a cloud without an image grid takes the slower path."""
    global _warned_unorganized
    if not _warned_unorganized:
        _warned_unorganized = True
        warnings.warn(
            f"{what} of {points} points has no image grid that proxseg could recognise: it is "
            "segmented as an unorganized cloud (voxel selection, no texture block, labels of "
            f"shape (N,)), {_UNORGANIZED_SLOWDOWN} on 640x480 mOSD scenes). To keep the grid, "
            "pass shape=(H, W) to proxseg.from_open3d when the cloud holds an image's H x W "
            "points in row-major order (o3d.io.read_point_cloud keeps an organized PCD's, NaN "
            "included), read the file with proxseg.read_point_cloud, or give the RGB-D image: "
            "proxseg.from_open3d(rgbd, intrinsic).", stacklevel=_caller_level())


def _warn_grey_once() -> None:
    """Says once per process that an RGB-D image's colour is grey (Open3D's default)."""
    global _warned_grey
    if not _warned_grey:
        _warned_grey = True
        warnings.warn(
            "the RGBDImage's colour is grey (one channel): Open3D's "
            "create_from_color_and_depth converts it to intensity by default, and proxseg's "
            "colour and texture blocks then run on grey (the same in R, G and B). Keep the "
            "colours with o3d.geometry.RGBDImage.create_from_color_and_depth(color, depth, ..., "
            "convert_rgb_to_intensity=False).", stacklevel=_caller_level())


def _looks_like_image(grid: np.ndarray) -> bool:
    """Whether points (H, W, 3) lie as a pinhole camera's image grid: x/z increasing along the
    rows and y/z down the columns, between neighbours that are both valid (z > 0)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        valid = np.isfinite(grid).all(axis=2) & (grid[..., 2] > 0)
        if valid.sum() < max(100, grid.shape[0] * grid.shape[1] // 100):
            return False
        u = grid[..., 0] / grid[..., 2]
        v = grid[..., 1] / grid[..., 2]
        along_rows = (u[:, 1:] > u[:, :-1])[valid[:, 1:] & valid[:, :-1]]
        down_columns = (v[1:] > v[:-1])[valid[1:] & valid[:-1]]
    if along_rows.size < 100 or down_columns.size < 100:
        return False
    return bool(along_rows.mean() >= _GRID_AGREEMENT and down_columns.mean() >= _GRID_AGREEMENT)


def image_grid(xyz: np.ndarray, sizes: Sequence[Tuple[int, int]] = SENSOR_SIZES
               ) -> Optional[Tuple[int, int]]:
    """The (H, W) of a common sensor whose image grid the points (N, 3) are, in row-major order,
    or None: N must be H x W and the points must look like that image (:func:`from_open3d`)."""
    n = len(xyz)
    for h, w in sizes:
        if h * w == n and _looks_like_image(xyz.reshape(h, w, 3)):
            return h, w
    return None


def _grid_shape(shape: Any, n: int) -> Tuple[int, int]:
    """The (H, W) given as shape=, checked against the cloud's N points."""
    try:
        h, w = (int(s) for s in shape)
    except (TypeError, ValueError):
        raise TypeError(f"shape: {shape!r} (expected (H, W), two positive integers)") from None
    if h < 1 or w < 1 or h * w != n:
        raise ValueError(f"shape: ({h}, {w}) holds {h * w} points but the cloud has {n} "
                         "(expected H x W == the number of points, row-major)")
    return h, w


def _image_array(image: Any) -> np.ndarray:
    """An Open3D image (legacy or tensor) as a numpy array."""
    if hasattr(image, "as_tensor"):  # open3d.t.geometry.Image
        image = image.as_tensor().numpy()
    return np.asarray(image)


def _intrinsic_matrix(intrinsic: Any) -> np.ndarray:
    """The 3x3 camera matrix of an Open3D PinholeCameraIntrinsic, a tensor or an array-like."""
    if hasattr(intrinsic, "intrinsic_matrix"):
        intrinsic = intrinsic.intrinsic_matrix
    if hasattr(intrinsic, "numpy"):
        intrinsic = intrinsic.numpy()
    k = np.asarray(intrinsic, dtype=np.float64)
    if k.shape != (3, 3):
        raise ValueError(f"intrinsic: shape {k.shape} (expected the 3x3 camera matrix or an "
                         "open3d.camera.PinholeCameraIntrinsic)")
    return k


def _rgbd_frame(geometry: Any, intrinsic: Any, depth_scale: Optional[float]) -> Frame:
    """The organized frame of an Open3D RGBDImage (legacy or tensor)."""
    if intrinsic is None:
        raise TypeError("an Open3D RGBDImage needs its camera: "
                        "proxseg.from_open3d(rgbd, intrinsic)")
    tensor = hasattr(geometry.depth, "as_tensor")
    depth = _image_array(geometry.depth)
    colour = _image_array(geometry.color)
    if depth.ndim == 3:
        depth = depth[..., 0]
    if colour.ndim == 3 and colour.shape[2] == 1:
        colour = colour[..., 0]
    if colour.ndim == 2:  # create_from_color_and_depth's default: converted to intensity
        _warn_grey_once()
        colour = np.repeat(colour[..., None], 3, axis=2)
    if colour.dtype != np.uint8:
        colour = np.clip(np.rint(colour.astype(np.float64) * 255.0), 0, 255).astype(np.uint8)
    scale = depth_scale if depth_scale is not None else (1000.0 if tensor else 1.0)
    if depth.dtype not in (np.uint16, np.float32, np.float64):
        depth = depth.astype(np.float32)
    return from_rgbd(colour[..., :3], depth, _intrinsic_matrix(intrinsic), scale)


def from_open3d(geometry: Any, intrinsic: Any = None, *, depth_scale: Optional[float] = None,
                shape: Optional[Tuple[int, int]] = None) -> Frame:
    """A :class:`Frame` from an Open3D geometry, organized whenever the image grid is known.

    Parameters
    ----------
    geometry : open3d.geometry.PointCloud, open3d.t.geometry.PointCloud,
            open3d.geometry.RGBDImage or open3d.t.geometry.RGBDImage
        A point cloud of H x W points in an image's row-major order becomes an organized frame
        (the fast path of :func:`segment`, labels of shape (H, W)): ``o3d.io.read_point_cloud``
        keeps every point of an organized PCD, NaN included, and that order, as
        ``PointCloud.create_from_rgbd_image(..., project_valid_depth_only=False)`` does. The
        grid is ``shape`` when given, else a common sensor size (640x480, 320x240, 1280x720,
        848x480, 1920x1080, 512x424, 640x400, ...: ``SENSOR_SIZES``) whose grid the points
        really are (x/z increasing along the rows and y/z down the columns, as a pinhole
        camera sees them). Any other cloud becomes an unorganized frame, a far slower path: a warning says
        so, and how to keep the grid, once per process. An RGB-D image keeps its grid, as
        :func:`read_rgbd` makes it; a grey one (Open3D's default
        ``convert_rgb_to_intensity=True``) is taken with its grey in R, G and B and a warning,
        once per process, that says how to keep the colours.
    intrinsic : open3d.camera.PinholeCameraIntrinsic, open3d.core.Tensor or array-like (3, 3)
        The camera of an RGB-D image (required for one, unused for a cloud).
    depth_scale : float, optional
        Depth units per metre of the RGB-D image's depth. Default: 1 for a legacy RGBDImage
        (its depth is in metres, as ``create_from_color_and_depth`` leaves it) and 1000 for a
        tensor one (raw sensor units).
    shape : tuple of int, optional
        (H, W): the cloud's points are an H x W image in row-major order. Always wins over the
        inference; H x W must be the number of points.

    Returns
    -------
    Frame

    Raises
    ------
    TypeError
        For another geometry, an RGB-D image without ``intrinsic`` or a shape that is not two
        integers.
    ValueError
        For a ``shape`` that does not hold the cloud's points, or colours outside [0, 1].
    """
    module, name = type(geometry).__module__, type(geometry).__name__
    if not module.startswith("open3d"):
        raise TypeError(f"{name}: expected an Open3D PointCloud or RGBDImage")
    if name == "RGBDImage":
        if shape is not None:
            raise TypeError("shape: only for point clouds (an RGBDImage has its own grid)")
        return _rgbd_frame(geometry, intrinsic, depth_scale)
    if name != "PointCloud":
        raise TypeError(f"{module}.{name}: expected an Open3D PointCloud or RGBDImage")
    if hasattr(geometry, "point"):  # open3d.t.geometry.PointCloud
        xyz = geometry.point.positions.numpy()
        rgb = geometry.point.colors.numpy() if "colors" in geometry.point else None
    else:  # open3d.geometry.PointCloud
        xyz = np.asarray(geometry.points)
        rgb = np.asarray(geometry.colors) if geometry.has_colors() else None
    xyz = np.asarray(xyz, dtype=np.float32).reshape(-1, 3)
    grid = _grid_shape(shape, len(xyz)) if shape is not None else image_grid(xyz)
    if grid is None:
        _warn_unorganized_once(f"an Open3D {name}", len(xyz))
        return Frame(xyz, rgb)
    h, w = grid
    return Frame(xyz.reshape(h, w, 3), None if rgb is None else rgb.reshape(h, w, -1))


def _colour_rows(colours: Any, n: int) -> np.ndarray:
    """Colours given per point of a frame of n points as float64 (n, 3) in [0, 1]."""
    c = np.asarray(colours, dtype=np.float64)
    if c.size != 3 * n or c.shape[-1] != 3:
        raise ValueError(f"colours: shape {c.shape} (expected float RGB in [0, 1], one row per "
                         f"point of the frame: {n} rows)")
    return c.reshape(-1, 3)


def frame_cloud(frame: Frame, *, colours: Any = None, indices: Any = None,
                attributes: Optional[Dict[str, np.ndarray]] = None, tensor: bool = False) -> Any:
    """The Open3D cloud of a frame's points with finite coordinates (of ``indices`` only when
    given), in the frame's row-major order: legacy, or tensor with the integer ``attributes``
    (one value per point of the frame) as (n, 1) Int32 attributes."""
    import open3d as o3d  # type: ignore[import]  # an optional dependency

    xyz = frame.xyz.reshape(-1, 3)
    rows = np.arange(len(xyz)) if indices is None else np.asarray(indices, dtype=np.int64)
    rows = rows[np.isfinite(xyz[rows]).all(axis=1)]
    if colours is not None:
        rgb = _colour_rows(colours, len(xyz))[rows]
    elif frame.rgb is not None:
        rgb = frame.rgb.reshape(-1, 3)[rows] / 255.0
    else:
        rgb = None
    if not tensor:
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz[rows].astype(np.float64)))
        if rgb is not None:
            cloud.colors = o3d.utility.Vector3dVector(rgb)
        return cloud
    cloud = o3d.t.geometry.PointCloud(o3d.core.Tensor(np.ascontiguousarray(xyz[rows])))
    if rgb is not None:
        cloud.point.colors = o3d.core.Tensor(rgb.astype(np.float32))
    for name, values in (attributes or {}).items():
        column = np.asarray(values).reshape(-1)[rows].astype(np.int32).reshape(-1, 1)
        cloud.point[name] = o3d.core.Tensor(column)
    return cloud


def to_open3d(x: Any, colours: Any = None, *, by: Optional[str] = None, tensor: bool = False,
              colors: Any = None) -> Any:
    """An Open3D geometry of a frame, a result, a candidate, an object or a box.

    Parameters
    ----------
    x : Frame, SegmentResult, RecognitionResult, Candidate, RecognizedObject or Box
        A frame: its valid points. A result: the frame's valid points coloured ``by`` and, as a
        tensor cloud, with Int32 attributes ``instance`` and ``label`` (a SegmentResult; a
        RecognitionResult adds ``object``, an index into ``result.object_names``). A candidate
        or an object: its own points. A box: an ``open3d.geometry.OrientedBoundingBox``.
    colours : array-like, optional
        For a frame only: float RGB in [0, 1] per point of the frame (its shape + (3,)), e.g.
        ``proxseg.label_colours(result.instances)``; default: the frame's own colours.
        ``colors=`` is accepted too.
    by : str, optional
        For a result: its ``to_open3d(by=...)`` (``"instances"``, ``"labels"``, ``"objects"``,
        ``"colours"`` or ``"colors"``).
    tensor : bool
        ``open3d.t.geometry.PointCloud`` (positions float32, colors float32 in [0, 1] and the
        attributes) instead of ``open3d.geometry.PointCloud``. Not for a box.

    Returns
    -------
    open3d.geometry.PointCloud, open3d.t.geometry.PointCloud or
    open3d.geometry.OrientedBoundingBox
        Clouds hold the points with finite coordinates only, in the frame's row-major order.

    Raises
    ------
    TypeError
        For anything else, or an argument that does not apply to ``x``.
    ValueError
        For colours of the wrong shape or an unknown ``by``.
    """
    from ._recognize import RecognitionResult, RecognizedObject
    from ._segment import Box, Candidate, SegmentResult

    colours = _one_colour(colours, colors)
    if isinstance(x, Frame):
        if by is not None:
            raise TypeError("by: only for a result (a Frame is coloured by colours=)")
        return frame_cloud(x, colours=colours, tensor=tensor)
    if colours is not None:
        raise TypeError(f"colours: only for a Frame (a {type(x).__name__} is coloured by by=)")
    if isinstance(x, Box):
        if tensor or by is not None:
            raise TypeError("a Box becomes an open3d.geometry.OrientedBoundingBox (no tensor=, "
                            "no by=)")
        return x.to_open3d()
    if isinstance(x, (Candidate, RecognizedObject)):
        if by is not None:
            raise TypeError(f"by: only for a result (a {type(x).__name__} keeps the scene's "
                            "colours)")
        return x.to_open3d(tensor=tensor)
    if isinstance(x, (SegmentResult, RecognitionResult)):
        return x.to_open3d(tensor=tensor) if by is None else x.to_open3d(by=by, tensor=tensor)
    raise TypeError(f"{type(x).__name__}: expected a proxseg Frame, SegmentResult, "
                    "RecognitionResult, Candidate, RecognizedObject or Box")
