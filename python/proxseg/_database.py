"""proxseg.Database: the model database [paper 3.4] on disk (docs/database.md)."""

from __future__ import annotations

import math
import os
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _proxseg
from ._frame import PathLike, as_frame


class Database:
    """A model database: named objects, each with partial views described once (normals, FPFH),
    in a directory holding one file, ``database.sqlite`` (docs/database.md). The same directory
    works with ``proxseg db`` and ``proxseg recognize --db``.

    ``Database(path)`` opens an existing database (OSError when it is missing; ValueError for a
    version-1 folder database, which ``proxseg db upgrade`` converts). Opening reads only the
    views' summaries; a view's points and features are read when recognition first needs them.
    ``Database(path, create=True)`` opens it, or starts a new empty one there (nothing is written
    until a view is added); ``voxel_size``, ``normal_radius`` (metres) and ``fpfh_radii``
    (metres) set a new database's descriptor.

    A database this process may not write (another user's, a read-only file, folder or mount)
    opens to read all the same, leaving no file beside it; an add, remove or rename then raises
    OSError naming the file (docs/database.md, "Readers without write access").

    Recognitions may read one Database from several threads at once and never wait for an add:
    each works on the database as it was when it started. Adds (from any thread or process)
    take turns and each lands whole.
    """

    def __init__(self, path: PathLike, *, create: bool = False,
                 voxel_size: Optional[float] = None, normal_radius: Optional[float] = None,
                 fpfh_radii: Optional[Sequence[float]] = None) -> None:
        self._db = _proxseg._Database(
            os.fspath(path), create, math.nan if voxel_size is None else float(voxel_size),
            math.nan if normal_radius is None else float(normal_radius),
            [float(r) for r in fpfh_radii] if fpfh_radii is not None else [])

    @property
    def path(self) -> str:
        """The database directory."""
        return self._db.path

    @property
    def objects(self) -> List[str]:
        """Object names, in order of first appearance."""
        return self._db.objects

    def __len__(self) -> int:
        """The number of views."""
        return len(self._db)

    def __repr__(self) -> str:
        return f"<proxseg.Database {self.path!r}: {len(self.objects)} objects, {len(self)} views>"

    @property
    def damaged(self) -> List[str]:
        """Views left out when the database was opened, their records damaged (where: what)."""
        return self._db.damaged

    def info(self) -> Dict[str, Any]:
        """What ``proxseg db info --json`` prints: the descriptor, per object its views, points
        and bytes, and the file's size."""
        return self._db.info()

    def check(self) -> Dict[str, Any]:
        """What ``proxseg db check --json`` finds: ``views``, ``whole`` (views whose records are
        all whole) and ``damaged`` (one line per damaged record: where and what)."""
        return self._db.check()

    def remove(self, object: str) -> int:
        """Removes every view of ``object`` from the database file; the number removed
        (ValueError when there is no such object)."""
        return self._db.remove(object)

    def rename(self, object: str, to: str) -> int:
        """Renames ``object`` to ``to`` (an existing name: the views join it); the number of views
        renamed."""
        return self._db.rename(object, to)

    def view(self, index: int) -> Dict[str, Any]:
        """View ``index``: object, name, source, points, coloured, and ``xyz`` (n, 3) float32, the
        voxel-filtered points in the model frame (metres). IndexError outside [0, len)."""
        return self._db.view(int(index))

    def add_view(self, object: str, points: Any, *, rgb: Optional[np.ndarray] = None,
                 viewpoint: Optional[Sequence[float]] = (0.0, 0.0, 0.0),
                 source: Optional[str] = None) -> Dict[str, Any]:
        """Adds one view of ``object`` and writes it to the database file (one transaction).

        Parameters
        ----------
        object : str
            The object's name.
        points : Frame, str, os.PathLike, array-like or Open3D PointCloud
            Its valid points in the model frame, metres.
        rgb : array-like, optional
            Colours of array points: uint8 0-255 or floats in [0, 1].
        viewpoint : sequence of 3 floats or None
            Where the sensor was in that frame (metres; the origin for a captured view), or
            None for a full model seen from everywhere (normals oriented outwards).
        source : str, optional
            What the view was made from, kept in the index (default: the path, or "python").

        Returns
        -------
        dict
            The view's entry: object, name, source, points, coloured.
        """
        frame = as_frame(points, rgb)
        if source is None:
            source = os.fspath(points) if isinstance(points, (str, os.PathLike)) else "python"
        given = (math.nan, math.nan, math.nan) if viewpoint is None else tuple(
            float(v) for v in viewpoint)
        if len(given) != 3:
            raise ValueError(f"viewpoint: {len(given)} values (expected x, y, z in metres or None)")
        vp = (given[0], given[1], given[2])
        return self._db.add_view(object, frame, vp, source)

    def render(self, object: str, mesh: PathLike, *, views: int = 8, units: str = "m",
               distance: float = 0.0, depth_noise: float = 0.0, seed: int = 1
               ) -> List[Dict[str, Any]]:
        """Renders partial views of a coloured mesh with a virtual depth camera on a sphere
        around it and adds them, as ``proxseg db render`` does [paper 3.4, Fig. 2].

        Parameters
        ----------
        object : str
            The object's name.
        mesh : str or os.PathLike
            PLY with vertex colours, or OBJ with its MTL and texture.
        views : int
            Cameras on the sphere.
        units : {"m", "mm"}
            The mesh's coordinates. A mesh over 5 m across in metres, or under 5 mm in
            millimetres, is refused (ValueError naming the other unit).
        distance : float
            Camera to the mesh's centre, metres (0 = automatic).
        depth_noise : float
            Standard deviation at 1 m, metres.
        seed : int
            Of the noise.

        Returns
        -------
        list of dict
            The entries of the views added (views that see almost nothing are skipped).
        """
        if units not in ("m", "mm"):
            raise ValueError(f"units: {units!r} (expected 'm' or 'mm')")
        return self._db.render(object, os.fspath(mesh), 0.001 if units == "mm" else 1.0,
                               int(views), float(distance), float(depth_noise), int(seed))


DatabaseLike = Union[Database, PathLike]


def as_database(db: DatabaseLike) -> Database:
    """A Database, or one loaded from a path."""
    if isinstance(db, Database):
        return db
    if isinstance(db, (str, os.PathLike)):
        return Database(db)
    raise TypeError(f"db: {type(db).__name__} (expected a proxseg.Database or a path)")
