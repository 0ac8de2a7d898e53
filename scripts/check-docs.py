#!/usr/bin/env python3
"""Checks the documentation's links: README.md is a front page, nothing links to nowhere.

Usage: check-docs.py [ROOT]

Over every Markdown file of the tree (README.md, CHANGELOG.md, CONTRIBUTING.md, docs/, each
folder's README.md; build trees and hidden folders skipped):
- every relative link and image (`[text](path)`, `![alt](path#anchor)`) names a file or folder
  that exists, and an anchor names a heading of the Markdown file it points into;
- every page of docs/ is reachable from README.md by following links;
- README.md has at most 120 lines (the front page; the rest belongs in docs/).
Links inside code (fenced blocks, `inline code`) are text, not links. Web addresses are not
fetched (CI has no network). Exit 0 when all holds, else 1 with one line per fault.
"""

import os
import re
import sys
from pathlib import Path

README_MAX_LINES = 120
LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
FENCE = re.compile(r"^\s*(```|~~~)")
INLINE_CODE = re.compile(r"`+[^`]*`+")
SKIPPED_DIRS = {"node_modules", "demo-out", "third_party"}


def markdown_files(root: Path):
    """Every .md file of the tree, build folders (those with a CMakeCache.txt) left out."""
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and d not in SKIPPED_DIRS
                         and not (Path(folder) / d / "CMakeCache.txt").exists())
        for name in sorted(files):
            if name.endswith(".md"):
                yield Path(folder) / name


def prose_lines(text: str):
    """(line number, line) outside fenced code, with inline code blanked."""
    fenced = False
    for number, line in enumerate(text.split("\n"), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield number, INLINE_CODE.sub("", line)


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces to dashes."""
    text = re.sub(r"[`*_]|\{#[^}]*\}", "", heading.strip().lower())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path: Path):
    """The anchors of a Markdown file's headings (GitHub numbers repeats -1, -2, ...)."""
    seen = {}
    out = set()
    for _, line in prose_lines(path.read_text(encoding="utf-8")):
        match = re.match(r"^#{1,6}\s+(.*)$", line)
        if match:
            base = slug(match.group(1))
            count = seen.get(base, 0)
            seen[base] = count + 1
            out.add(base if count == 0 else f"{base}-{count}")
    return out


def links_of(path: Path):
    """(line number, target) of every relative link of a Markdown file."""
    for number, line in prose_lines(path.read_text(encoding="utf-8")):
        for match in LINK.finditer(line):
            target = match.group(1)
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):  # http:, mailto:, ...
                continue
            yield number, target


def check(root: Path):
    """The faults found, one line each."""
    faults = []
    graph = {}
    for path in markdown_files(root):
        rel = path.relative_to(root)
        graph[path.resolve()] = set()
        for number, target in links_of(path):
            file_part, _, anchor = target.partition("#")
            dest = (path.parent / file_part).resolve() if file_part else path.resolve()
            where = f"{rel}:{number}: {target}"
            if not dest.exists():
                faults.append(f"{where}: no such file")
                continue
            if anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                faults.append(f"{where}: no heading with the anchor #{anchor}")
            if dest.suffix == ".md":
                graph[path.resolve()].add(dest)
    readme = root / "README.md"
    if not readme.exists():
        return faults + ["README.md: missing"]
    lines = readme.read_text(encoding="utf-8").count("\n")
    if lines > README_MAX_LINES:
        faults.append(f"README.md: {lines} lines (at most {README_MAX_LINES}: the front page; "
                      "move the rest to docs/ and link it from the index)")
    reached, todo = set(), [readme.resolve()]
    while todo:
        page = todo.pop()
        if page not in reached:
            reached.add(page)
            todo.extend(graph.get(page, ()))
    for page in sorted((root / "docs").glob("*.md")):
        if page.resolve() not in reached:
            faults.append(f"{page.relative_to(root)}: not reachable from README.md's links")
    return faults


def main() -> int:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent)
    faults = check(root.resolve())
    for fault in faults:
        print(f"check-docs: {fault}", file=sys.stderr)
    return 1 if faults else 0


if __name__ == "__main__":
    sys.exit(main())
