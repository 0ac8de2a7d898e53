"""proxseg.segment(): regions and candidate objects of a scene [paper 3.1-3.3]."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Union

import numpy as np

from . import _page, _proxseg
from ._frame import as_frame
from ._open3d import frame_cloud
from ._proxseg import Frame
from ._params import SegmentParams, resolve_segment_params


@dataclass(frozen=True)
class Box:
    """An oriented bounding box, metres: ``centre`` (3,), ``axes`` (3, 3) with the axes as
    columns (largest extent first, right-handed) and ``extent`` (3,) the side lengths."""

    centre: np.ndarray
    axes: np.ndarray
    extent: np.ndarray

    @property
    def center(self) -> np.ndarray:
        """The same as ``centre``."""
        return self.centre

    def to_open3d(self) -> Any:
        """The box as Open3D's: ``open3d.geometry.OrientedBoundingBox(centre, axes, extent)``
        (its ``R`` has the axes as columns)."""
        import open3d as o3d  # type: ignore[import]  # an optional dependency

        return o3d.geometry.OrientedBoundingBox(np.asarray(self.centre, dtype=np.float64),
                                                np.asarray(self.axes, dtype=np.float64),
                                                np.asarray(self.extent, dtype=np.float64))


@dataclass(frozen=True)
class Candidate:
    """One instance of the selection [3.3]: a candidate object, or the background (a large
    supporting plane: table, floor, wall).

    Attributes
    ----------
    id : int
        Its value in ``SegmentResult.instances`` (1..n), the report's ``"id"``.
    label : int
        The segmentation label it came from.
    indices : numpy.ndarray
        Indices into the frame's points (flattened row-major when organized), ascending.
        ``points`` is the same array (the name it had before).
    centroid : numpy.ndarray
        (3,) metres.
    box : Box
        Its oriented bounding box.
    background : bool
        True for a supporting plane, which is not a candidate object.
    frame : Frame or None
        The frame segmented (``to_open3d`` uses it).
    """

    id: int
    label: int
    indices: np.ndarray
    centroid: np.ndarray
    box: Box
    background: bool
    frame: Optional[Frame] = field(default=None, repr=False, compare=False)

    def to_open3d(self, *, tensor: bool = False) -> Any:
        """Its points as an Open3D cloud, in the scene's colours.

        Parameters
        ----------
        tensor : bool
            ``open3d.t.geometry.PointCloud`` (positions, colors, and Int32 ``instance`` and
            ``label`` attributes, its id and label) instead of ``open3d.geometry.PointCloud``.

        Raises
        ------
        ValueError
            For a candidate without its frame (made by hand).
        """
        if self.frame is None:
            raise ValueError("to_open3d: this candidate has no frame (those of proxseg.segment "
                             "do)")
        n = len(self.frame)
        return frame_cloud(self.frame, indices=self.indices, tensor=tensor,
                           attributes={"instance": np.full(n, self.id),
                                       "label": np.full(n, self.label)})

    @property
    def points(self) -> np.ndarray:
        """The same as ``indices`` (its earlier name; they are point indices, not points)."""
        return self.indices

    def __repr__(self) -> str:
        c = ", ".join(f"{x:.3f}" for x in self.centroid)
        e = ", ".join(f"{x:.3f}" for x in self.box.extent)
        return (f"Candidate(id={self.id}, points={len(self.indices)}, centroid=({c}), "
                f"extent=({e}){', background' if self.background else ''})")


@dataclass(frozen=True)
class SegmentResult(_page.PageMixin):
    """What :func:`segment` returns.

    Attributes
    ----------
    labels : numpy.ndarray
        Segmentation label per point (uint32; 0 = invalid or none), the frame's shape: (H, W)
        when organized, else (N,). The paper's k-means + MRF labels 1..k when they were computed
        (``report["paper_labels"]``: the paper preset, unorganized clouds,
        ``paper_labels=True``); otherwise the image-grid surfaces the selection started from.
    labels_kmeans : numpy.ndarray
        The same before the MRF (equal to ``labels`` for surfaces).
    instances : numpy.ndarray
        Instance per point (uint32; 0 = none, else a Candidate.id), the frame's shape.
    candidates : list of Candidate
        The candidate objects (background planes excluded), in id order.
    background : list of Candidate
        The background instances.
    k : int
        Number of the paper's segmentation labels (0 when they were not computed).
    times_ms : dict
        Wall time of each stage and "total", milliseconds.
    params : SegmentParams
        The parameters used.
    report : dict
        The CLI's JSON report (``proxseg segment --json``): input, parameters, version and
        commit, times, counts, energies.
    frame : Frame
        The frame segmented (``save`` and ``to_open3d`` use it).
    """

    labels: np.ndarray
    labels_kmeans: np.ndarray
    instances: np.ndarray
    candidates: List[Candidate]
    background: List[Candidate]
    k: int
    times_ms: Dict[str, float]
    params: SegmentParams
    report: Dict[str, Any] = field(repr=False)
    frame: Optional[Frame] = field(default=None, repr=False, compare=False)

    def save(self, prefix: Union[str, "os.PathLike[str]"], *, outputs: str = "pcd,png,json"
             ) -> List[str]:
        """Writes the files ``proxseg segment -o PREFIX`` writes: the PCD and the pictures byte
        for byte the CLI's, the report with this run's times.

        Parameters
        ----------
        prefix : str or os.PathLike
            ``PREFIX.pcd`` (fields label and instance), ``PREFIX.png`` (the picture),
            ``PREFIX.json`` (the report), and with ``labels`` ``PREFIX.label.png`` and
            ``PREFIX.instance.png``. Written all or none.
        outputs : str
            Comma-separated ``labels``, ``pcd``, ``png``, ``json``, ``html`` (the 3D page), or
            ``all`` (the CLI's ``--outputs``).

        Returns
        -------
        list of str
            The files written.

        Raises
        ------
        ValueError
            For an unknown output name, or a result without its frame.
        OSError
            When a file cannot be written.
        """
        if self.frame is None:
            raise ValueError("save: this result has no frame (results of proxseg.segment do)")
        return _proxseg._write_segmentation(os.fspath(prefix), self.frame, self.labels,
                                            self.instances, self.report, outputs,
                                            int(self.params.threads))

    def to_html(self, title: str = "segmentation") -> str:
        """The 3D page of this result, as ``proxseg view`` writes it (docs/viewing.md): one
        self-contained HTML document with the cloud coloured by the scene's colours, the
        labels (k-means and MRF where computed) and the instances, a legend, picking and the
        candidates' boxes.

        Raises
        ------
        ValueError
            For a result without its frame.
        """
        if self.frame is None:
            raise ValueError("to_html: this result has no frame (results of proxseg.segment do)")
        fields = [("label", self.labels), ("instance", self.instances)]
        if self.report.get("paper_labels") and self.params.mrf.enabled:
            fields.insert(0, ("label_kmeans", self.labels_kmeans))
        return _proxseg._view_page(self.frame, fields, self.report, title)

    def to_open3d(self, by: str = "instances", *, tensor: bool = False) -> Any:
        """The frame's valid points as an Open3D cloud coloured by result.

        Parameters
        ----------
        by : {"instances", "labels", "colours", "colors"}
            Colour each point by its instance or segmentation label (``label_colours``), or
            keep the scene's colours.
        tensor : bool
            ``open3d.t.geometry.PointCloud`` with positions (float32), colors (float32 in
            [0, 1], chosen by ``by``) and the Int32 attributes ``instance`` and ``label`` (n, 1),
            instead of ``open3d.geometry.PointCloud``.

        Returns
        -------
        open3d.geometry.PointCloud or open3d.t.geometry.PointCloud
            The points with finite coordinates, in the frame's row-major order; a candidate's
            own cloud is ``candidate.to_open3d()``.
        """
        if self.frame is None:
            raise ValueError("to_open3d: this result has no frame (results of proxseg.segment do)")
        kinds = {"instances": self.instances, "labels": self.labels, "colours": None,
                 "colors": None}
        if by not in kinds:
            raise ValueError(f"by: {by!r} (expected 'instances', 'labels', 'colours' or 'colors')")
        chosen = kinds[by]
        colours = None if chosen is None else label_colours(chosen)
        return frame_cloud(self.frame, colours=colours, tensor=tensor,
                           attributes={"instance": self.instances, "label": self.labels})

    def __repr__(self) -> str:
        return (f"SegmentResult(k={self.k}, candidates={len(self.candidates)}, "
                f"background={len(self.background)}, shape={self.labels.shape}, "
                f"total_ms={self.times_ms.get('total', 0):.1f})")


def label_colours(labels: np.ndarray) -> np.ndarray:
    """A colour per label for display.

    Parameters
    ----------
    labels : array-like of int
        Labels or instances of a result (any shape).

    Returns
    -------
    numpy.ndarray
        Float64 RGB in [0, 1] of shape ``labels.shape + (3,)``: black for 0, distinct hues by
        golden-ratio steps otherwise; the same label, the same colour. Reshaped to (-1, 3) it
        colours ``open3d.geometry.PointCloud.colors`` point for point (:meth:`SegmentResult.to_open3d`).
    """
    labels = np.asarray(labels)
    hue = np.mod(labels.astype(np.float64) * 0.618033988749895, 1.0) * 6.0
    s, v = 0.7, 0.95
    sector = np.floor(hue).astype(np.int64) % 6
    f = hue - np.floor(hue)
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    vv = np.full_like(hue, v)
    pp = np.full_like(hue, p)
    r = np.choose(sector, [vv, q, pp, pp, t, vv])
    g = np.choose(sector, [t, vv, vv, q, pp, pp])
    b = np.choose(sector, [pp, pp, t, vv, vv, q])
    out = np.stack([r, g, b], axis=-1)
    out[labels == 0] = 0.0
    return out


label_colors = label_colours  # the same function, under the other spelling


def _candidates(report: Dict[str, Any], points: List[np.ndarray], frame: Optional[Frame]
                ) -> List[Candidate]:
    out = []
    # The extension's points are in instance order, as candidates and background interleave.
    rows = sorted(report["candidates"] + report["background"], key=lambda c: c["id"])
    for c, p in zip(rows, points):
        box = c["box"]
        out.append(Candidate(id=c["id"], label=c["label"], indices=p,
                             centroid=np.array(c["centroid"]),
                             box=Box(np.array(box["centre"]), np.array(box["axes"]).T,
                                     np.array(box["extent"])),
                             background=c["background"], frame=frame))
    return out


def _params_object(tree: Dict[str, Any]) -> SegmentParams:
    p = SegmentParams.__new__(SegmentParams)
    super(SegmentParams, p).__init__(tree, "")
    return p


def segmentation_result(raw: Dict[str, Any], frame: Optional[Frame] = None) -> SegmentResult:
    """A SegmentResult from the extension's dict (also used by recognize)."""
    report = raw["report"]
    instances = _candidates(report, raw["candidate_points"], frame)
    return SegmentResult(labels=raw["labels"], labels_kmeans=raw["labels_kmeans"],
                         instances=raw["instances"],
                         candidates=[c for c in instances if not c.background],
                         background=[c for c in instances if c.background], k=report["k"],
                         times_ms=dict(report["times_ms"]),
                         params=_params_object(report["parameters"]), report=report, frame=frame)


def segment(frame: Any, params: Optional[Any] = None, *, preset: Optional[str] = None,
            rgb: Optional[np.ndarray] = None, **overrides: Any) -> SegmentResult:
    """Segments a scene into regions and candidate objects, without training [paper 3.1-3.3]:
    voxels, colour / texture / shape features, Algorithm 1 + k-means, the Potts MRF, selection.

    Parameters
    ----------
    frame : Frame, str, os.PathLike, array-like or Open3D geometry
        A :class:`Frame`; a file path; points (N, 3) or (H, W, 3) in metres (NaN = no return)
        with ``rgb`` beside them; an Open3D PointCloud (organized when it holds an image grid
        :func:`from_open3d` recognises, e.g. ``o3d.io.read_point_cloud`` of an organized PCD;
        otherwise the far slower unorganized path, said once) or RGB-D image
        (:func:`from_open3d`). Without colour the colour and texture blocks are off (the
        report says so).
    params : SegmentParams or dict, optional
        Laid out like the JSON config; partial dicts are applied over the preset.
    preset : {"default", "paper"}, optional
        The best measured settings, or exactly the paper's.
    rgb : array-like, optional
        Colours of array points: uint8 0-255 or floats in [0, 1].
    **overrides
        Parameters by name, over ``params``: a section as a dict (``mrf={"enabled": False}``)
        or any parameter by its own name when that is unique (``voxel_size=0.01``,
        ``threads=2``). :func:`parameters` lists them; lengths in metres.

    Returns
    -------
    SegmentResult
        Per-point ``labels`` and ``instances`` in the frame's shape, the ``candidates``,
        ``times_ms`` and the ``params`` used; ``save()`` writes the CLI's files. Equal to the
        CLI's ``proxseg segment`` with the same parameters, whatever ``threads`` is.

    Raises
    ------
    ValueError
        For a bad frame or parameter (the message names the field).
    TypeError
        For an argument of the wrong kind.

    Notes
    -----
    The GIL is released while it runs: threads may segment at once.
    """
    f = as_frame(frame, rgb)
    tree = resolve_segment_params(params, preset, overrides)
    return segmentation_result(_proxseg._segment(f, tree), f)
