#!/usr/bin/env bash
# README.md's quick start runs as written, on nothing but what proxseg makes itself: the commands
# of its first sh block after "## Quick start", in an empty folder, with the built proxseg first
# on PATH; each must exit 0 and the files they name must appear.
set -euo pipefail
root=$1 bin=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
commands=$(awk '/^## Quick start/ {q = 1} q && /^```sh/ {b = 1; next} b && /^```/ {exit} b' \
  "$root/README.md" | sed 's/[[:space:]]*#.*$//')
[ -n "$commands" ] || { echo "quickstart: no sh block under '## Quick start' in README.md" >&2; exit 1; }
cd "$work"
export PATH="$bin:$PATH"
while IFS= read -r line; do
  [ -z "$line" ] && continue
  echo "quickstart: $line" >&2
  bash -c "$line" >/dev/null || { echo "quickstart: failed: $line" >&2; exit 1; }
done <<<"$commands"
for f in scene.pcd out/scene.pcd out/scene.png out/scene.json out/scene.html out/rec.json; do
  [ -s "$f" ] || { echo "quickstart: $f was not made" >&2; exit 1; }
done
grep -q '"name": "box"' out/rec.json || { echo "quickstart: recognize named no box" >&2; exit 1; }
