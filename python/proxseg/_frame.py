"""Frames from files, numpy arrays, RGB-D images and Open3D point clouds."""

from __future__ import annotations

import os
import sys
import types
import warnings
from typing import Any, Dict, Optional, Union

import numpy as np

from . import _proxseg
from ._proxseg import Frame

PathLike = Union[str, "os.PathLike[str]"]


def read_point_cloud(path: PathLike, *, label_field: str = "label") -> Frame:
    """Reads a point cloud file into a :class:`Frame`.

    Parameters
    ----------
    path : str or os.PathLike
        ``.pcd`` (ascii, binary or binary_compressed; organized or not; fields x y z and
        optionally rgb/rgba) or ``.ply`` (vertices, optionally with colours). A cloud without
        colour is read without it (``frame.rgb is None``).
    label_field : str
        An integer PCD field kept as ``frame.label`` (e.g. ``"instance"`` of the CLI's output).

    Returns
    -------
    Frame
        Organized (H x W) when the file is.

    Raises
    ------
    FileNotFoundError, PermissionError, IsADirectoryError, OSError
        When the file cannot be opened.
    ValueError
        When its content is not a valid point cloud (the message names the file, line or field
        and what was expected).
    """
    return _proxseg.read_point_cloud(os.fspath(path), label_field)


def read_rgbd(colour: Optional[PathLike] = None, depth: Optional[PathLike] = None, *,
              meta: Optional[PathLike] = None, intrinsics: Optional[PathLike] = None,
              color: Optional[PathLike] = None) -> Frame:
    """Reads an RGB-D pair of images into an organized :class:`Frame`, as the CLI's
    ``--colour/--depth`` do.

    Parameters
    ----------
    colour : str or os.PathLike
        8-bit PNG or JPEG (``color=`` is accepted too).
    depth : str or os.PathLike
        16-bit PNG in depth units (0 = no return).
    meta : str or os.PathLike, optional
        A YCB-Video ``-meta.json`` (intrinsic_matrix, factor_depth); or
    intrinsics : str or os.PathLike, optional
        A JSON file ``{"fx", "fy", "cx", "cy", "depth_scale"}``. Exactly one of the two.

    Returns
    -------
    Frame
        Organized, the images' size; points in metres.
    """
    colour = _one_colour(colour, color)
    if colour is None or depth is None:
        raise TypeError("read_rgbd: needs the colour and the depth image")
    return _proxseg.read_rgbd(os.fspath(colour), os.fspath(depth),
                              meta=os.fspath(meta) if meta is not None else "",
                              intrinsics=os.fspath(intrinsics) if intrinsics is not None else "")


def _one_colour(colour: Any, color: Any) -> Any:
    """The colour argument, given under either spelling (not both)."""
    if colour is not None and color is not None:
        raise TypeError("give colour or color, not both (the same argument)")
    return colour if colour is not None else color


def from_rgbd(colour: Optional[np.ndarray] = None, depth: Optional[np.ndarray] = None,
              K: Any = None, depth_scale: float = 1000.0, *,
              color: Optional[np.ndarray] = None) -> Frame:
    """An organized :class:`Frame` from a colour and a depth image in memory.

    Parameters
    ----------
    colour : numpy.ndarray or None
        (H, W, 3) uint8 RGB, or None for a colourless frame (``color=`` is accepted too).
    depth : numpy.ndarray
        (H, W) uint16 in depth units, or float32/float64 (0 or NaN = no return).
    K : array-like
        The 3x3 camera matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] in pixels.
    depth_scale : float
        Depth units per metre (1000 for millimetres, YCB-Video: 10000; 1.0 for a float depth in
        metres).

    Returns
    -------
    Frame
        Points ((u - cx) z / fx, (v - cy) z / fy, z) with z = depth / depth_scale, exactly as
        :func:`read_rgbd` computes them.
    """
    if depth is None or K is None:
        raise TypeError("from_rgbd: needs the depth image and the camera matrix K")
    return _proxseg._from_rgbd(_one_colour(colour, color), np.asarray(depth),
                               np.asarray(K, dtype=np.float64), float(depth_scale))


_warned_unorganized = False


def _warn_unorganized_once(what: str) -> None:
    """Says once per process that a cloud without an image grid takes the slower path."""
    global _warned_unorganized
    if not _warned_unorganized:
        _warned_unorganized = True
        warnings.warn(
            f"{what} has no image grid: proxseg segments it as an unorganized cloud (voxel "
            "selection, no texture block, about 3x slower, labels of shape (N,)). To keep the "
            "grid, read the file with proxseg.read_point_cloud, or pass the RGB-D image to "
            "proxseg.from_open3d(rgbd, intrinsic).", stacklevel=_caller_level())


def _caller_level() -> int:
    """The stacklevel of the first caller outside this package (the user's line)."""
    here = os.path.dirname(os.path.abspath(__file__))
    level = 1
    frame: Optional[types.FrameType] = sys._getframe(1)
    while frame is not None and os.path.dirname(os.path.abspath(frame.f_code.co_filename)) == here:
        level += 1
        frame = frame.f_back
    return level


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


def _image_array(image: Any) -> np.ndarray:
    """An Open3D image (legacy or tensor) as a numpy array."""
    if hasattr(image, "as_tensor"):  # open3d.t.geometry.Image
        image = image.as_tensor().numpy()
    return np.asarray(image)


def from_open3d(geometry: Any, intrinsic: Any = None, *, depth_scale: Optional[float] = None
                ) -> Frame:
    """A :class:`Frame` from an Open3D geometry.

    Parameters
    ----------
    geometry : open3d.geometry.PointCloud, open3d.t.geometry.PointCloud,
            open3d.geometry.RGBDImage or open3d.t.geometry.RGBDImage
        A point cloud becomes an unorganized frame (Open3D clouds have no image grid; a warning
        says so once per process). An RGB-D image keeps its grid: the frame is organized, as
        :func:`read_rgbd` makes it.
    intrinsic : open3d.camera.PinholeCameraIntrinsic, open3d.core.Tensor or array-like (3, 3)
        The camera of an RGB-D image (required for one, unused for a cloud).
    depth_scale : float, optional
        Depth units per metre of the RGB-D image's depth. Default: 1 for a legacy RGBDImage
        (its depth is in metres, as ``create_from_color_and_depth`` leaves it) and 1000 for a
        tensor one (raw sensor units).

    Returns
    -------
    Frame

    Raises
    ------
    TypeError
        For another geometry, or an RGB-D image without ``intrinsic``.
    """
    module, name = type(geometry).__module__, type(geometry).__name__
    if not module.startswith("open3d"):
        raise TypeError(f"{name}: expected an Open3D PointCloud or RGBDImage")
    if name == "RGBDImage":
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
        if colour.ndim == 2:  # legacy default: converted to intensity
            colour = np.repeat(colour[..., None], 3, axis=2)
        if colour.dtype != np.uint8:
            colour = np.clip(np.rint(colour.astype(np.float64) * 255.0), 0, 255).astype(np.uint8)
        scale = depth_scale if depth_scale is not None else (1000.0 if tensor else 1.0)
        if depth.dtype not in (np.uint16, np.float32, np.float64):
            depth = depth.astype(np.float32)
        return from_rgbd(colour[..., :3], depth, _intrinsic_matrix(intrinsic), scale)
    if name != "PointCloud":
        raise TypeError(f"{module}.{name}: expected an Open3D PointCloud or RGBDImage")
    if hasattr(geometry, "point"):  # open3d.t.geometry.PointCloud
        xyz = geometry.point.positions.numpy()
        rgb = geometry.point.colors.numpy() if "colors" in geometry.point else None
    else:  # open3d.geometry.PointCloud
        xyz = np.asarray(geometry.points)
        rgb = np.asarray(geometry.colors) if geometry.has_colors() else None
    _warn_unorganized_once(f"an Open3D {name}")
    return Frame(np.asarray(xyz, dtype=np.float32), rgb)


def as_frame(data: Any, rgb: Any = None) -> Frame:
    """The :class:`Frame` for what proxseg's functions accept as a cloud.

    Parameters
    ----------
    data : Frame, str or os.PathLike, array-like, or Open3D geometry
        A Frame as it is; a path read by :func:`read_point_cloud`; points (N, 3) or (H, W, 3)
        in metres (a numpy array, nested lists, anything ``numpy.asarray`` takes); an Open3D
        PointCloud or RGBDImage (:func:`from_open3d`; an RGBDImage needs its camera there).
    rgb : array-like, optional
        Colours of array points: uint8 0-255, or floats in [0, 1].

    Returns
    -------
    Frame
    """
    if isinstance(data, Frame):
        if rgb is not None:
            raise ValueError("rgb: given with a Frame (expected the colours inside the Frame)")
        return data
    if isinstance(data, (str, os.PathLike)):
        return read_point_cloud(data)
    if type(data).__module__.startswith("open3d"):
        return from_open3d(data)
    if isinstance(data, (np.ndarray, list, tuple)) or hasattr(data, "__array__"):
        return Frame(data, rgb)
    raise TypeError(f"{type(data).__name__}: expected a proxseg.Frame, a path, an array of "
                    "points (N, 3) or (H, W, 3), or an Open3D PointCloud / RGBDImage")


def write_point_cloud(path: PathLike, frame: Frame, *, fields: Optional[Dict[str, Any]] = None,
                      compressed: bool = True) -> None:
    """Writes a frame as a PCD file (organized when the frame is), as the CLI writes its clouds.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.pcd`` file to write; written whole or not at all (a temporary file and a rename).
    frame : Frame
        Its points (NaN kept) and colours (field ``rgb``, when it has them).
    fields : dict of str to array-like, optional
        Extra unsigned integer fields, one value per point (e.g. ``{"label": result.labels,
        "instance": result.instances}``).
    compressed : bool
        ``DATA binary_compressed`` (PCL's and Open3D's readers read it) or ``binary``.

    Raises
    ------
    ValueError
        For a path that does not end in .pcd or a field of the wrong size.
    OSError
        When the file cannot be written.
    """
    target = os.fspath(path)
    if not target.lower().endswith(".pcd"):
        raise ValueError(f"{target}: expected a .pcd path (proxseg writes PCD files)")
    _proxseg._write_point_cloud(target, frame, dict(fields or {}), compressed)


def to_open3d(frame: Frame, colours: Optional[np.ndarray] = None) -> Any:
    """The frame's valid points as an ``open3d.geometry.PointCloud``.

    Parameters
    ----------
    frame : Frame
    colours : numpy.ndarray, optional
        Float RGB in [0, 1] per point of the frame (its shape + (3,)), e.g.
        ``proxseg.label_colours(result.instances)``; default: the frame's own colours.

    Returns
    -------
    open3d.geometry.PointCloud
        Points with finite coordinates only, in the frame's row-major order.
    """
    import open3d as o3d  # type: ignore[import]  # an optional dependency

    xyz = frame.xyz.reshape(-1, 3)
    keep = np.isfinite(xyz).all(axis=1)
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz[keep].astype(np.float64)))
    if colours is not None:
        c = np.asarray(colours, dtype=np.float64).reshape(-1, 3)
        if len(c) != len(xyz):
            raise ValueError(f"colours: {len(c)} rows (expected one per point, {len(xyz)})")
        cloud.colors = o3d.utility.Vector3dVector(c[keep])
    elif frame.rgb is not None:
        cloud.colors = o3d.utility.Vector3dVector(frame.rgb.reshape(-1, 3)[keep] / 255.0)
    return cloud
