"""The 3D page of a result in Jupyter and in a browser: ``_repr_html_`` and ``show()`` of
:class:`SegmentResult` and :class:`RecognitionResult` (the page is ``proxseg view``'s)."""

from __future__ import annotations

import html
import os
import tempfile
import webbrowser
from pathlib import Path
from typing import Union


def iframe(page: str, height: int = 600) -> str:
    """The page inside an iframe (its script runs in notebooks that do not run a cell's own)."""
    return (f'<iframe srcdoc="{html.escape(page, quote=True)}" style="width: 100%; '
            f'height: {height}px; border: 0" sandbox="allow-scripts"></iframe>')


def show(page: str, path: Union[str, "os.PathLike[str]", None] = None,
         browser: bool = True) -> str:
    """Writes page to path (a temporary file when None) and opens it in the default browser
    when browser is true (and one is there); returns the file's path."""
    if path is None:
        fd, name = tempfile.mkstemp(prefix="proxseg-", suffix=".html")
        os.close(fd)
        path = name
    with open(path, "w", encoding="utf-8") as f:
        f.write(page)
    if browser:
        # Path.as_uri percent-encodes the path's bytes: a '#', '?' or '%' in it stays a name.
        webbrowser.open(Path(os.path.abspath(path)).as_uri())
    return os.fspath(path)


class PageMixin:
    """``_repr_html_`` (the page in Jupyter) and ``show()`` of a result whose ``to_html()``
    makes its 3D page."""

    def to_html(self, title: str = "proxseg") -> str:
        raise NotImplementedError

    def _repr_html_(self) -> str:
        return iframe(self.to_html())

    def show(self, path: Union[str, "os.PathLike[str]", None] = None, *,
             browser: bool = True) -> str:
        """Writes the 3D page (:meth:`to_html`) to ``path`` (a temporary file when None) and
        opens it in the default browser unless ``browser`` is false; returns the file's path."""
        return show(self.to_html(), path, browser)
