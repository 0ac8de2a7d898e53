"""Frames from files, numpy arrays, RGB-D images and Open3D point clouds."""

from __future__ import annotations

import os
from typing import Any, Optional, Union

import numpy as np

from . import _proxseg
from ._proxseg import Frame

PathLike = Union[str, "os.PathLike[str]"]


def read_point_cloud(path: PathLike, *, label_field: str = "label") -> Frame:
    """Reads a point cloud file into a :class:`Frame`.

    path: ``.pcd`` (ascii, binary or binary_compressed; organized or not; fields x y z and
        optionally rgb/rgba) or ``.ply`` (vertices, optionally with colours). A cloud without
        colour is read without it (``frame.rgb is None``).
    label_field: an integer PCD field kept as ``frame.label`` (e.g. ``"instance"`` of the
        CLI's output PCD).

    Raises OSError when the file cannot be opened, ValueError when its content is not a valid
    point cloud (the message names the file, line or field and what was expected).
    """
    return _proxseg.read_point_cloud(os.fspath(path), label_field)


def read_rgbd(color: PathLike, depth: PathLike, *, meta: Optional[PathLike] = None,
              intrinsics: Optional[PathLike] = None) -> Frame:
    """Reads an RGB-D pair of images into an organized :class:`Frame`, as the CLI's
    ``--color/--depth`` do.

    color: 8-bit PNG or JPEG. depth: 16-bit PNG (0 = no return).
    meta: a YCB-Video ``-meta.json`` (intrinsic_matrix, factor_depth), or
    intrinsics: a JSON file ``{"fx", "fy", "cx", "cy", "depth_scale"}`` (exactly one of them).
    """
    return _proxseg.read_rgbd(os.fspath(color), os.fspath(depth),
                              meta=os.fspath(meta) if meta is not None else "",
                              intrinsics=os.fspath(intrinsics) if intrinsics is not None else "")


def from_rgbd(color: Optional[np.ndarray], depth: np.ndarray, K: Any,
              depth_scale: float = 1000.0) -> Frame:
    """An organized :class:`Frame` from a colour and a depth image in memory.

    color: (H, W, 3) uint8 RGB, or None for a colourless frame.
    depth: (H, W) uint16 in depth units, or float32/float64 (0 or NaN = no return).
    K: the 3x3 camera matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] in pixels.
    depth_scale: depth units per metre (1000 for millimetres, YCB-Video: 10000; 1.0 for a
        float depth in metres).

    Points are ((u - cx) z / fx, (v - cy) z / fy, z) with z = depth / depth_scale, exactly as
    :func:`read_rgbd` computes them.
    """
    return _proxseg._from_rgbd(color, np.asarray(depth), np.asarray(K, dtype=np.float64),
                               float(depth_scale))


def _open3d_frame(cloud: Any) -> Optional[Frame]:
    """A Frame from an Open3D point cloud (legacy or tensor), or None if it is not one. Open3D
    colours are floats in [0, 1]; they become uint8."""
    module = type(cloud).__module__
    if not module.startswith("open3d"):
        return None
    name = type(cloud).__name__
    if name != "PointCloud":
        raise TypeError(f"{module}.{name}: expected an open3d PointCloud")
    if hasattr(cloud, "point"):  # open3d.t.geometry.PointCloud
        xyz = cloud.point.positions.numpy()
        rgb = cloud.point.colors.numpy() if "colors" in cloud.point else None
    else:  # open3d.geometry.PointCloud
        xyz = np.asarray(cloud.points)
        rgb = np.asarray(cloud.colors) if cloud.has_colors() else None
    if rgb is not None and rgb.dtype != np.uint8:
        rgb = np.clip(np.rint(np.asarray(rgb, dtype=np.float64) * 255.0), 0, 255).astype(np.uint8)
    return Frame(np.asarray(xyz, dtype=np.float32), rgb)


def as_frame(data: Any, rgb: Optional[np.ndarray] = None) -> Frame:
    """The :class:`Frame` for what the functions of proxseg accept as a cloud: a Frame, a path
    (read_point_cloud), a numpy array of points (N, 3) or (H, W, 3) with optional ``rgb``, or an
    Open3D ``geometry.PointCloud`` / ``t.geometry.PointCloud``."""
    if isinstance(data, Frame):
        if rgb is not None:
            raise ValueError("rgb: given with a Frame (expected the colours inside the Frame)")
        return data
    if isinstance(data, (str, os.PathLike)):
        return read_point_cloud(data)
    if isinstance(data, np.ndarray):
        return Frame(data, rgb)
    frame = _open3d_frame(data)
    if frame is not None:
        return frame
    raise TypeError(f"{type(data).__name__}: expected a proxseg.Frame, a path, a numpy array "
                    "(N, 3) or (H, W, 3), or an open3d PointCloud")
