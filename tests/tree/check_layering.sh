#!/usr/bin/env bash
# The dependency direction of proxseg's parts: core -> io -> recognition -> eval (CMakeLists.txt). Fails, naming
# file and line, when a header or source of a part includes a header of a later part, when a
# private helper in src/util/ includes any proxseg header, or when a source reaches into another
# part's private files with a relative include.
# Usage: tests/tree/check_layering.sh [ROOT]   (ROOT: the source tree, default the one holding tests/)
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/../.." && pwd)}
cd "$root"

# The parts, in order; a part may include its own headers and those of the parts before it.
parts=(core io recognition eval)
bad=0
allowed() {  # PART -> the parts it may include, as an alternation for grep -E
  local out=""
  for p in "${parts[@]}"; do
    out+="${out:+|}$p"
    [[ $p == "$1" ]] && break
  done
  echo "$out"
}

for part in "${parts[@]}"; do
  ok=$(allowed "$part")
  mapfile -t files < <(find "include/proxseg/$part" "src/$part" \( -name '*.hpp' -o -name '*.cpp' \
    -o -name '*.hpp.in' \) 2>/dev/null | sort)
  ((${#files[@]})) || continue
  # <proxseg/PART/...> of a later part.
  while IFS= read -r hit; do
    echo "$hit  <- $part includes a later part" >&2
    bad=1
  done < <(grep -nE '^\s*#\s*include\s*<proxseg/' "${files[@]}" /dev/null | grep -vE "<proxseg/($ok)/" || true)
  # "..." includes with a folder: only the part's own private files (by their path from src/,
  # "io/formats/pcd_header.hpp") and src/util/.
  while IFS= read -r hit; do
    echo "$hit  <- $part includes another part's private file" >&2
    bad=1
  done < <(grep -nE '^\s*#\s*include\s*"[^"]*/' "${files[@]}" /dev/null |
    grep -vE "\"(util/[a-z_]+|$part/[a-z_/]+)\.hpp\"" || true)
done

# The Python bindings build on core, io and recognition, not on eval (python/, docs/architecture.md).
while IFS= read -r hit; do
  echo "$hit  <- python/ includes eval" >&2
  bad=1
done < <(grep -nE '^\s*#\s*include\s*<proxseg/eval/' python/src/*.[ch]pp /dev/null 2>/dev/null || true)

# Private helpers shared by all parts depend on none of them (one helper may build on another:
# value noise on the splitmix hash).
while IFS= read -r hit; do
  echo "$hit  <- a src/util helper includes a proxseg header" >&2
  bad=1
done < <(grep -nE '^\s*#\s*include\s*(<proxseg/|")' src/util/*.hpp /dev/null |
  grep -vE '#\s*include\s*"util/[a-z_]+\.hpp"' || true)

if ((bad)); then
  echo "check_layering: the dependency direction core -> io -> recognition -> eval is broken (see above)" >&2
  exit 1
fi
echo "check_layering: core -> io -> recognition -> eval holds ($(find include/proxseg src -name '*.[ch]pp' | wc -l) files)"
