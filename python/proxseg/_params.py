"""Parameters as the JSON config lays them out, with attribute access.

``SegmentParams`` and ``RecognitionParams`` hold the same names, sections and values as the
``"parameters"`` of the CLI's reports and its ``--config`` files (docs/method.md says what each
one does). The C++ library checks them: a wrong name or value raises ``ValueError`` naming the
field.
"""

from __future__ import annotations

import copy
import difflib
import warnings
from typing import Any, Dict, Iterator, List, Mapping, Optional, Type

from . import _proxseg


class _Section:
    """One section of a parameter tree (``voxels``, ``mrf``, ``registration``...): attribute
    access to its values; setting a name it does not have raises ``AttributeError``."""

    __slots__ = ("_data", "_path")

    def __init__(self, data: Dict[str, Any], path: str) -> None:
        object.__setattr__(self, "_data", data)
        object.__setattr__(self, "_path", path)

    def __getattr__(self, name: str) -> Any:
        data = object.__getattribute__(self, "_data")
        if name not in data:
            section, name = self._renamed_or_raise(name)
            return getattr(section, name)
        value = data[name]
        return _Section(value, self._where(name)) if isinstance(value, dict) else value

    def __setattr__(self, name: str, value: Any) -> None:
        data = object.__getattribute__(self, "_data")
        if name not in data:
            section, name = self._renamed_or_raise(name)
            setattr(section, name, value)
        elif isinstance(data[name], dict):
            if not isinstance(value, Mapping):
                raise ValueError(f"{self._where(name)}: a section (expected a dict of its values)")
            _merge(data[name], dict(value), self._where(name), _renamed())
        else:
            data[name] = value

    def _renamed_or_raise(self, name: str) -> "tuple[_Section, str]":
        """For an old spelling of a name (``selection.image_normal_step``): the section that
        holds it now and its new name, with a ``DeprecationWarning``; else AttributeError."""
        data = object.__getattribute__(self, "_data")
        path = object.__getattribute__(self, "_path")
        new = _renamed().get(self._where(name))
        if not new or not new.startswith(f"{path}." if path else ""):
            raise AttributeError(f"{self._where(name)}: no such parameter"
                                 f"{_did_you_mean(name, data)}")
        warnings.warn(f"{self._where(name)} is now {new} (the old key will be removed)",
                      DeprecationWarning, stacklevel=3)
        section: _Section = self
        for part in (new[len(path) + 1:] if path else new).split(".")[:-1]:
            section = getattr(section, part)
        return section, new.rsplit(".", 1)[-1]

    def __dir__(self) -> Iterator[str]:
        return iter(sorted(object.__getattribute__(self, "_data")))

    def __iter__(self) -> Iterator[str]:
        return iter(object.__getattribute__(self, "_data"))

    def __getitem__(self, name: str) -> Any:
        return self.__getattr__(name)

    def __setitem__(self, name: str, value: Any) -> None:
        self.__setattr__(name, value)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, _Section):
            return self.to_dict() == other.to_dict()
        if isinstance(other, Mapping):
            return self.to_dict() == dict(other)
        return NotImplemented

    def _where(self, name: str) -> str:
        path = object.__getattribute__(self, "_path")
        return f"{path}.{name}" if path else name

    def to_dict(self) -> Dict[str, Any]:
        """A deep copy as plain dicts (the JSON config's layout)."""
        return copy.deepcopy(object.__getattribute__(self, "_data"))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({object.__getattribute__(self, '_data')!r})"

    def __reduce__(self) -> Any:
        # Pickling (multiprocessing, Dask): the tree of values, rebuilt without __init__.
        return (_rebuild, (type(self), self.to_dict(), object.__getattribute__(self, "_path")))


def _rebuild(kind: Type["_Section"], data: Dict[str, Any], path: str) -> "_Section":
    section = object.__new__(kind)
    _Section.__init__(section, data, path)
    return section


def _leaves(tree: Dict[str, Any], path: str = "") -> Iterator[str]:
    """The keys of every value below ``tree``, sections joined by dots ("image.normal_step")."""
    for name, value in tree.items():
        key = f"{path}.{name}" if path else name
        if isinstance(value, dict):
            yield from _leaves(value, key)
        else:
            yield key


def _did_you_mean(name: str, tree: Dict[str, Any]) -> str:
    """" (did you mean section.name?)" for a likely typo of a parameter's name, else ""."""
    keys = list(_leaves(tree))
    names = list(tree) + keys + [k.rsplit(".", 1)[-1] for k in keys]
    near = difflib.get_close_matches(name, names, n=1, cutoff=0.75)
    if not near and len(name) >= 4:  # a part of the name ("pairwise" for "pairwise_weight")
        near = [n for n in names if name in n][:1]
    return f" (did you mean {near[0]}?)" if near else ""


# The segmentation parameters' old spellings (before the selection's sections: "selection.
# image_normal_step", and the bare "image_normal_step") -> their keys now.
_RENAMED: Dict[str, str] = {}


def _renamed() -> Dict[str, str]:
    if not _RENAMED:
        rows = _proxseg._parameter_table("segmentation")
        old = {row["old_key"]: row["key"] for row in rows if row["old_key"]}
        bare: Dict[str, List[str]] = {}
        for key, new in old.items():
            bare.setdefault(key.rsplit(".", 1)[-1], []).append(new)
        _RENAMED.update({name: news[0] for name, news in bare.items() if len(news) == 1})
        _RENAMED.update(old)
    return _RENAMED


def _set_key(tree: Dict[str, Any], key: str, value: Any) -> None:
    *sections, name = key.split(".")
    for section in sections:
        tree = tree[section]
    tree[name] = value


def _merge(tree: Dict[str, Any], overrides: Dict[str, Any], path: str = "",
           renamed: Optional[Dict[str, str]] = None) -> None:
    """Sets the values of ``overrides`` in ``tree``: a section name with a dict merges into that
    section; a parameter name that is unique across the sections below may be given without them
    (``voxel_size=0.01`` for ``voxels={"voxel_size": 0.01}``). A key in ``renamed`` (an old
    spelling) sets its new key, with a ``DeprecationWarning``."""
    renamed = renamed or {}
    for name, value in overrides.items():
        where = f"{path}.{name}" if path else name
        if name in tree:
            if isinstance(tree[name], dict):
                if not isinstance(value, Mapping):
                    raise ValueError(f"{where}: a section (expected a dict of its values, "
                                    f"e.g. {name}={{{next(iter(tree[name]), 'name')!r}: ...}})")
                _merge(tree[name], dict(value), where, renamed)
            else:
                tree[name] = value
            continue
        owners = [k for k in _leaves(tree) if "." in k and k.rsplit(".", 1)[-1] == name]
        new = renamed.get(where) or (renamed.get(name) if not owners else None)
        if new and new.startswith(f"{path}." if path else ""):
            warnings.warn(f"{where} is now {new} (the old key will be removed)",
                          DeprecationWarning, stacklevel=4)
            _set_key(tree, new[len(path) + 1:] if path else new, value)
        elif len(owners) == 1:
            _set_key(tree, owners[0], value)
        elif owners:
            given = ", ".join(f"{path}.{k}" if path else k for k in owners)
            raise ValueError(f"{where}: in several sections ({given}); give it with its section")
        else:
            raise ValueError(f"{where}: no such parameter{_did_you_mean(name, tree)}")


class SegmentParams(_Section):
    """Every parameter of :func:`proxseg.segment` [paper 3.1-3.3], one section per stage:
    ``voxels``, ``features``, ``clustering``, ``kmeans``, ``mrf``, ``selection`` (with its
    sections ``voxels``, ``image``, ``occlusion`` and ``containers``) and ``threads``.

    ``SegmentParams(preset="default", **overrides)``: ``preset`` is ``"default"`` (the best
    measured settings) or ``"paper"`` (exactly the paper's); overrides as in
    :func:`proxseg.segment`. Lengths are in metres, angles in degrees.

    >>> p = proxseg.SegmentParams(preset="paper", voxel_size=0.01)
    >>> p.mrf.pairwise_weight
    0.275
    >>> p.mrf.enabled = False
    """

    def __init__(self, preset: str = "default", **overrides: Any) -> None:
        super().__init__(resolve_segment_params(None, preset, overrides), "")


class RecognitionParams(_Section):
    """Every parameter of :func:`proxseg.recognize` [paper 3.4]: the ``registration`` section
    (RANSAC, ICP, distances in metres) and the naming rule (``score``, ``min_score``,
    ``min_margin``, ``shortlist``, ``seed``...).

    ``RecognitionParams(**overrides)``: the defaults with overrides as in
    :func:`proxseg.recognize`.
    """

    def __init__(self, **overrides: Any) -> None:
        super().__init__(resolve_recognition_params(None, overrides), "")


# Preset trees by name, and ("checked", name) -> the checked tree segment() passes on unchanged.
_SEGMENT_DEFAULTS: Dict[Any, Dict[str, Any]] = {}


def _preset_tree(preset: str) -> Dict[str, Any]:
    if preset not in _SEGMENT_DEFAULTS:
        _SEGMENT_DEFAULTS[preset] = _proxseg._segment_params(preset, {})
    return copy.deepcopy(_SEGMENT_DEFAULTS[preset])


def _as_tree(params: Any, kind: Type[_Section], what: str) -> Dict[str, Any]:
    if isinstance(params, kind):
        return params.to_dict()
    if isinstance(params, Mapping):
        return copy.deepcopy(dict(params))
    raise TypeError(f"{what}: {type(params).__name__} (expected {kind.__name__} or a dict)")


def resolve_segment_params(params: Any, preset: Optional[str],
                           overrides: Mapping[str, Any]) -> Dict[str, Any]:
    """The complete, checked segmentation parameters: ``preset`` (default "default"), then
    ``params`` (SegmentParams or a dict, possibly partial), then ``overrides``."""
    if params is None and not overrides:  # a preset as it is: checked once (read-only, shared)
        key = ("checked", preset or "default")
        if key not in _SEGMENT_DEFAULTS:
            _SEGMENT_DEFAULTS[key] = _proxseg._segment_params(preset or "default", {})
        return _SEGMENT_DEFAULTS[key]
    if isinstance(params, SegmentParams) and preset is None:
        tree = params.to_dict()
    else:
        tree = _preset_tree(preset or "default")
        if params is not None:
            _merge(tree, _as_tree(params, SegmentParams, "params"), "", _renamed())
    _merge(tree, dict(overrides), "", _renamed())
    return _proxseg._segment_params(preset or "default", tree)


def resolve_recognition_params(params: Any, overrides: Mapping[str, Any]) -> Dict[str, Any]:
    """The complete, checked recognition parameters: the defaults, then ``params``
    (RecognitionParams or a dict, possibly partial), then ``overrides``."""
    tree = _proxseg._recognition_params({})
    if params is not None:
        _merge(tree, _as_tree(params, RecognitionParams, "params"), "")
    _merge(tree, dict(overrides))
    return _proxseg._recognition_params(tree)


def parameters(which: str = "segmentation") -> List[Dict[str, Any]]:
    """The parameter table: every parameter with its type, default, range, unit, help and the
    paper's value, as ``proxseg params --json`` prints it (docs/parameters.md).

    Parameters
    ----------
    which : {"segmentation", "recognition"}

    Returns
    -------
    list of dict
        One dict per parameter: ``key`` ("voxels.voxel_size"), ``section``, ``name``, ``type``,
        ``default``, ``range``, ``unit``, ``help``, ``paper``, ``flag`` (the CLI's), ``choices``,
        ``old_key`` (the key before the selection's sections, still read with a
        ``DeprecationWarning``; "" when it never changed).
    """
    if which not in ("segmentation", "recognition"):
        raise ValueError(f"which: {which!r} (expected 'segmentation' or 'recognition')")
    return list(_proxseg._parameter_table(which))
