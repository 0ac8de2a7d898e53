#!/usr/bin/env python3
"""Checks that docs/architecture.md maps every source and header to its concept: each file of
include/proxseg/, src/, apps/ and python/src/ is named there by its path (a table row), and
every path the map names exists. Prints what is missing or stale and exits 1.

Usage: scripts/check-architecture-map.py [ROOT]
"""
import pathlib
import re
import sys


def main(argv):
    root = pathlib.Path(argv[0] if argv else pathlib.Path(__file__).resolve().parent.parent)
    doc = (root / "docs" / "architecture.md").read_text()
    named = set(re.findall(r"`((?:include|src|apps|python/src)/[\w/.+-]+\.(?:cpp|hpp|hpp\.in))`",
                           doc))
    files = set()
    for folder in ("include/proxseg", "src", "apps", "python/src"):
        for path in (root / folder).rglob("*"):
            if path.suffix in (".cpp", ".hpp") or path.name.endswith(".hpp.in"):
                files.add(path.relative_to(root).as_posix())
    bad = 0
    for f in sorted(files - named):
        print(f"docs/architecture.md does not map {f} to its concept")
        bad = 1
    for f in sorted(named - files):
        print(f"docs/architecture.md names {f}, which does not exist")
        bad = 1
    return bad


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
