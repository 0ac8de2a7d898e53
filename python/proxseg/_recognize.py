"""proxseg.recognize() and recognize_object(): which known object each candidate is, with its
pose [paper 3.4, Algorithms 2-3]."""

from __future__ import annotations

import copy
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Type, Union

import numpy as np

from . import _page, _proxseg
from ._database import DatabaseLike, as_database
from ._frame import as_frame
from ._open3d import frame_cloud
from ._proxseg import Frame
from ._params import RecognitionParams, SegmentParams, _Section, resolve_recognition_params
from ._params import resolve_segment_params
from ._segment import SegmentResult, label_colours, segmentation_result


@dataclass(frozen=True)
class RecognizedObject:
    """One object of a scene (or the one cloud of :func:`recognize_object`).

    Attributes
    ----------
    id : int
        Its value in ``RecognitionResult.object_ids`` (1..n; 0 for recognize_object).
    name : str
        The object of the best view, or "unknown" (best score under min_score, or its lead over
        the runner-up under min_margin when not confident).
    score, fitness, coverage, rmse : float
        Of the best view (0 when none was aligned); rmse in metres.
    colour : float
        The colour agreement of the best view's explained points (1 without colour).
    pose : numpy.ndarray or None
        (4, 4) rigid transform, scene (camera) frame <- model frame, metres; None when no view
        was aligned.
    view : str or None
        The best view's name in the database.
    runner_up : tuple or None
        (name, score) of the best view of another object.
    indices : numpy.ndarray
        Frame point indices it holds (flattened row-major when organized), ascending;
        ``points`` is the same array (its earlier name).
    centroid : numpy.ndarray
        (3,) metres.
    instances : list of int
        The SegmentResult candidates it holds points of.
    origin : str
        "candidate", "split" or "merged" (recognition's split and merge passes).
    report : dict
        Its entry of the CLI's ``proxseg recognize`` JSON report.
    frame : Frame or None
        The frame recognised (``to_open3d`` uses it).
    """

    id: int
    name: str
    score: float
    fitness: float
    coverage: float
    colour: float
    rmse: float
    pose: Optional[np.ndarray]
    view: Optional[str]
    runner_up: Optional[tuple]
    indices: np.ndarray
    centroid: np.ndarray
    instances: List[int]
    origin: str
    report: Dict[str, Any] = field(repr=False)
    frame: Optional[Frame] = field(default=None, repr=False, compare=False)

    def to_open3d(self, *, tensor: bool = False) -> Any:
        """Its points as an Open3D cloud, in the scene's colours.

        Parameters
        ----------
        tensor : bool
            ``open3d.t.geometry.PointCloud`` (positions, colors and the Int32 attribute
            ``object``, its id) instead of ``open3d.geometry.PointCloud``.
        """
        if self.frame is None:
            raise ValueError("to_open3d: this object has no frame (those of proxseg.recognize "
                             "do)")
        return frame_cloud(self.frame, indices=self.indices, tensor=tensor,
                           attributes={"object": np.full(len(self.frame), self.id)})

    @property
    def points(self) -> np.ndarray:
        """The same as ``indices`` (its earlier name; they are point indices, not points)."""
        return self.indices

    @property
    def color(self) -> float:
        """The same as ``colour``."""
        return self.colour

    @property
    def known(self) -> bool:
        """Whether it was named (not "unknown")."""
        return self.name != "unknown"


@dataclass(frozen=True)
class RecognitionResult(_page.PageMixin):
    """What :func:`recognize` and :func:`recognize_object` return.

    Attributes
    ----------
    objects : list of RecognizedObject
        In id order. ``names``, ``scores`` ((n,)) and ``poses`` ((n, 4, 4), NaN where none)
        gather their fields.
    object_ids : numpy.ndarray or None
        Per point the id of the object holding it (0 = none), the frame's shape (recognize
        only; None for recognize_object).
    segmentation : SegmentResult or None
        The segmentation the scene's candidates came from (recognize only).
    times_ms : dict
        "segment", "recognize" (wall, milliseconds).
    params : dict
        {"segmentation": SegmentParams, "recognition": RecognitionParams} used.
    frame : Frame
        The frame recognised (``save`` and ``to_open3d`` use it).
    """

    objects: List[RecognizedObject]
    object_ids: Optional[np.ndarray]
    segmentation: Optional[SegmentResult]
    times_ms: Dict[str, float]
    params: Dict[str, _Section]
    frame: Optional[Frame] = field(default=None, repr=False, compare=False)
    # What save() writes from (C++ objects, not picklable: None after pickling).
    _output: Any = field(default=None, repr=False, compare=False)

    def save(self, prefix: Union[str, "os.PathLike[str]"], *, outputs: str = "pcd,png,json"
             ) -> List[str]:
        """Writes the files ``proxseg recognize ... -o PREFIX`` writes.

        Parameters
        ----------
        prefix : str or os.PathLike
            A scene: ``PREFIX.pcd`` (field ``object``), ``PREFIX.png`` (the picture with its
            legend), ``PREFIX.json`` (the report), and with ``labels`` ``PREFIX.object.png``;
            one object (:func:`recognize_object`): ``PREFIX.json`` and ``PREFIX.png``. Written
            all or none.
        outputs : str
            Comma-separated ``labels``, ``pcd``, ``png``, ``json``, ``html`` (the 3D page), or
            ``all``.

        Returns
        -------
        list of str
            The paths of the files written, as given by ``prefix``.

        Raises
        ------
        ValueError
            For an unknown output name, or a result that was pickled (the models' views it
            draws stay with the process that recognised).
        OSError
            When a file cannot be written.
        """
        if self._output is None or self.frame is None:
            raise ValueError("save: this result was pickled; save it where it was recognised")
        return _proxseg._write_recognition(os.fspath(prefix), self.frame, self._output, outputs)

    def to_html(self, title: str = "recognition") -> str:
        """The 3D page of this result, as ``proxseg view`` writes it (docs/viewing.md): the
        scene coloured by its colours or by object, the legend (name, score), picking (name,
        score, fitness, coverage, pose) and each named object's box and axes at its pose.

        Raises
        ------
        ValueError
            For the result of recognize_object (no scene), or one that was pickled.
        """
        if self.frame is None or self.object_ids is None or self._output is None:
            raise ValueError("to_html: only a scene's result (recognize), where it was "
                             "recognised (not after pickling), has a page")
        return _proxseg._recognition_view_page(self.frame, self._output, title)

    def to_open3d(self, by: str = "objects", *, tensor: bool = False) -> Any:
        """The frame's valid points as an Open3D cloud coloured by result.

        Parameters
        ----------
        by : {"objects", "instances", "labels", "colours", "colors"}
            Colour each point by its object (``label_colours(object_ids)``; black for points of
            no object), its segmentation instance or label, or keep the scene's colours. The
            result of :func:`recognize_object` (one object, no per-point ids) has its scene's
            colours whatever ``by`` is.
        tensor : bool
            ``open3d.t.geometry.PointCloud`` with positions (float32), colors (float32 in
            [0, 1], chosen by ``by``) and the Int32 attributes (n, 1) ``object`` (the object's
            id, 0 for none: an index into :attr:`object_names`), ``instance`` and ``label``
            (the segmentation's), instead of ``open3d.geometry.PointCloud``. A recognize_object
            result has no attributes.

        Returns
        -------
        open3d.geometry.PointCloud or open3d.t.geometry.PointCloud
            The points with finite coordinates, in the frame's row-major order; an object's own
            cloud is ``result.objects[i].to_open3d()``.
        """
        if self.frame is None:
            raise ValueError("to_open3d: this result has no frame")
        seg = self.segmentation
        kinds = {"objects": self.object_ids, "colours": None, "colors": None,
                 "instances": None if seg is None else seg.instances,
                 "labels": None if seg is None else seg.labels}
        if by not in kinds:
            raise ValueError(f"by: {by!r} (expected 'objects', 'instances', 'labels', 'colours' "
                             "or 'colors')")
        attributes = {}
        if self.object_ids is not None:
            attributes["object"] = self.object_ids
        if seg is not None:
            attributes.update(instance=seg.instances, label=seg.labels)
        chosen = kinds[by]
        colours = None if chosen is None else label_colours(chosen)
        return frame_cloud(self.frame, colours=colours, tensor=tensor, attributes=attributes)

    @property
    def object_names(self) -> List[str]:
        """The name of each object id, ``""`` at 0 (no object): the ``object`` attribute of
        ``to_open3d(tensor=True)`` indexes it, and ``numpy.array(object_names)[object_ids]``
        names every point."""
        names = [""] * (max((o.id for o in self.objects), default=0) + 1)
        for o in self.objects:
            names[o.id] = o.name
        return names

    def __getstate__(self) -> Dict[str, Any]:
        state = dict(self.__dict__)
        state["_output"] = None
        return state

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self.__dict__.update(state)

    @property
    def names(self) -> List[str]:
        return [o.name for o in self.objects]

    @property
    def scores(self) -> np.ndarray:
        return np.array([o.score for o in self.objects], dtype=np.float64)

    @property
    def poses(self) -> np.ndarray:
        nan = np.full((4, 4), np.nan)
        return np.array([o.pose if o.pose is not None else nan for o in self.objects],
                        dtype=np.float64).reshape(-1, 4, 4)

    def __repr__(self) -> str:
        return f"RecognitionResult({', '.join(f'{o.id}: {o.name} {o.score:.2f}' for o in self.objects)})"


def _object(raw: Dict[str, Any], frame: Frame) -> RecognizedObject:
    r = raw["report"]
    best = r.get("best")
    runner = r.get("runner_up")
    return RecognizedObject(
        id=r["id"], name=r["name"], score=r.get("score", 0.0), fitness=r.get("fitness", 0.0),
        coverage=r.get("coverage", 0.0), colour=(best or {}).get("colour", 1.0),
        rmse=(best or {}).get("rmse", 0.0),
        pose=np.array(r["pose"], dtype=np.float64) if "pose" in r else None,
        view=(best or {}).get("view"),
        runner_up=(runner["name"], runner["score"]) if runner else None, indices=raw["points"],
        centroid=np.array(r["centroid"]), instances=list(r["instances"]), origin=r["origin"],
        report=r, frame=frame)


def _params(tree: Dict[str, Any], kind: Type[_Section]) -> _Section:
    p = object.__new__(kind)
    _Section.__init__(p, tree, "")
    return p


def recognize(frame: Any, db: DatabaseLike, params: Optional[Any] = None, *,
              segment_params: Optional[Any] = None, preset: Optional[str] = None,
              rgb: Optional[np.ndarray] = None, **overrides: Any) -> RecognitionResult:
    """Segments a scene and names every candidate object from the model database, with its pose
    [paper 3.1-3.4]: what ``proxseg recognize SCENE --db DB`` does.

    Parameters
    ----------
    frame : Frame, str, os.PathLike, array-like or Open3D geometry
        As for :func:`segment`.
    db : Database, str or os.PathLike
        A :class:`Database` (load it once for many frames) or its directory.
    params : RecognitionParams or dict, optional
        JSON layout; partial dicts over the defaults.
    segment_params, preset : optional
        The segmentation's parameters, as ``params`` and ``preset`` of :func:`segment`.
    rgb : array-like, optional
        Colours of array points.
    **overrides
        Recognition parameters by name (``min_score=0.6``, ``shortlist=0``,
        ``registration={"icp_iterations": 50}``, ``seed=2``).

    Returns
    -------
    RecognitionResult
        Objects with names, scores and 4x4 poses; per-point ``object_ids``; the segmentation.
        Equal to the CLI's answer for the same input and parameters.

    Raises
    ------
    ValueError
        For bad input or parameters.
    OSError
        For a database that cannot be read (FileNotFoundError when it does not exist).
    """
    f = as_frame(frame, rgb)
    database = as_database(db)
    seg = resolve_segment_params(segment_params, preset, {})
    rec = resolve_recognition_params(params, overrides)
    raw = _proxseg._recognize_scene(f, database._db, seg, rec, _input_name(frame))
    ids = raw["object_ids"]
    return RecognitionResult(
        objects=[_object(o, f) for o in raw["objects"]], object_ids=ids,
        segmentation=segmentation_result(raw["segmentation"], f), times_ms=dict(raw["times_ms"]),
        params={"segmentation": _params(copy.deepcopy(seg), SegmentParams),
                "recognition": _params(rec, RecognitionParams)},
        frame=f, _output=raw["output"])


def recognize_object(points: Any, db: DatabaseLike, params: Optional[Any] = None, *,
                     rgb: Optional[np.ndarray] = None, **overrides: Any) -> RecognitionResult:
    """Names one already segmented object cloud from the model database, with its pose
    [paper 3.4, Algorithm 3]: what ``proxseg recognize --object CLOUD --db DB`` does.

    Parameters
    ----------
    points : Frame, str, os.PathLike, array-like or Open3D PointCloud
        The object's points (N, 3) in metres, in the sensor frame (sensor at the origin).
    db : Database, str or os.PathLike
    params : RecognitionParams or dict, optional
    rgb : array-like, optional
    **overrides
        As for :func:`recognize`.

    Returns
    -------
    RecognitionResult
        One object (id 0) and no segmentation.
    """
    f = as_frame(points, rgb)
    database = as_database(db)
    rec = resolve_recognition_params(params, overrides)
    raw = _proxseg._recognize_object(f, database._db, rec, _input_name(points))
    return RecognitionResult(objects=[_object(o, f) for o in raw["objects"]], object_ids=None,
                             segmentation=None, times_ms=dict(raw["times_ms"]),
                             params={"recognition": _params(rec, RecognitionParams)},
                             frame=f, _output=raw["output"])


def _input_name(data: Any) -> str:
    """The report's "input": the file's path, or "python" for data in memory."""
    return os.fspath(data) if isinstance(data, (str, os.PathLike)) else "python"
