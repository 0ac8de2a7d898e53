"""Frames from files, numpy arrays and RGB-D images; point cloud files written (PCD, PLY)."""

from __future__ import annotations

import os
import sys
import types
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
        An integer PCD field or PLY vertex property kept as ``frame.label`` (e.g.
        ``"instance"`` of the CLI's output or of :func:`write_point_cloud`'s ``fields``).

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


def _caller_level() -> int:
    """The stacklevel of the first caller outside this package (the user's line)."""
    here = os.path.dirname(os.path.abspath(__file__))
    level = 1
    frame: Optional[types.FrameType] = sys._getframe(1)
    while frame is not None and os.path.dirname(os.path.abspath(frame.f_code.co_filename)) == here:
        level += 1
        frame = frame.f_back
    return level


def as_frame(data: Any, rgb: Any = None) -> Frame:
    """The :class:`Frame` for what proxseg's functions accept as a cloud.

    Parameters
    ----------
    data : Frame, str or os.PathLike, array-like, or Open3D geometry
        A Frame as it is; a path read by :func:`read_point_cloud`; points (N, 3) or (H, W, 3)
        in metres (a numpy array, nested lists, a buffer such as a ``memoryview``: anything
        ``numpy.asarray`` takes, as :class:`Frame` does); an Open3D
        PointCloud (:func:`from_open3d`: organized when it holds an image grid it can
        recognise; pass ``from_open3d(cloud, shape=(H, W))`` to be sure) or RGBDImage (which
        needs its camera: ``from_open3d(rgbd, intrinsic)``).
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
        from ._open3d import from_open3d  # imports this module

        return from_open3d(data)
    if isinstance(data, (np.ndarray, list, tuple)) or hasattr(data, "__array__") or \
            _is_buffer(data):
        return Frame(data, rgb)
    raise TypeError(f"{type(data).__name__}: expected a proxseg.Frame, a path, an array of "
                    "points (N, 3) or (H, W, 3), or an Open3D PointCloud / RGBDImage")


def _is_buffer(data: Any) -> bool:
    """Whether data has the buffer protocol (memoryview, array.array, ...), which Frame, through
    numpy.asarray, takes as well as arrays."""
    try:
        memoryview(data)
    except TypeError:
        return False
    return True


def write_point_cloud(path: PathLike, frame: Frame, *, fields: Optional[Dict[str, Any]] = None,
                      compressed: bool = True, keep_invalid: bool = False) -> None:
    """Writes a frame as a PCD file (organized when the frame is), as the CLI writes its clouds,
    or as a PLY file.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.pcd`` or ``.ply`` file to write; written whole or not at all (a temporary file
        and a rename).
    frame : Frame
        Its points and colours (PCD: field ``rgb``; PLY: ``red green blue`` uchar, when it has
        them).
    fields : dict of str to array-like, optional
        Extra unsigned integer fields, one value per point of the frame (e.g. ``{"label":
        result.labels, "instance": result.instances}``). PCD: ``U`` 4-byte fields; PLY:
        ``int`` properties (the type Open3D's tensor reader reads), values up to 2^31 - 1.
    compressed : bool
        PCD only: ``DATA binary_compressed`` (PCL's and Open3D's readers read it) or ``binary``.
    keep_invalid : bool
        PLY only. PLY has no image grid (an organized frame's WIDTH/HEIGHT are lost) and no
        notion of an invalid point: by default only the points with finite coordinates are
        written, in the frame's row-major order, as viewers and mesh tools expect. True writes
        every point, NaN coordinates kept (Open3D's and PCL's PLY readers keep them), so that
        vertex i is the frame's point i. A PCD keeps every point and the grid.

    Raises
    ------
    ValueError
        For a path that does not end in .pcd or .ply, a field of the wrong size or name, a PLY
        field value above 2^31 - 1, or a PLY of no valid point.
    OSError
        When the file cannot be written.
    """
    target = os.fspath(path)
    if not target.lower().endswith((".pcd", ".ply")):
        raise ValueError(f"{target}: expected a .pcd or .ply path (the formats proxseg writes)")
    _proxseg._write_point_cloud(target, frame, dict(fields or {}), bool(compressed),
                                bool(keep_invalid))
