#!/usr/bin/env bash
# Checks that two builds of the CLI write byte-identical outputs (labelled PCD and picture; the
# JSON reports differ only in their times, version and commit, which are dropped before the
# comparison): `proxseg segment` on the 45 mOSD learn scenes and `proxseg recognize` on the
# YCB-Video frames against their three models, each at 1 and 2 threads. For restructuring that
# must not change what proxseg answers (issue 16, acceptance 5).
# Usage: scripts/same-outputs.sh OLD_PROXSEG NEW_PROXSEG [DATA]   (DATA: ../shared/data)
set -euo pipefail
old=$1 new=$2 data=${3:-../shared/data}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
frames=$data/ycbv/frames

# Strips what legitimately differs between two builds and runs: times, version, commit; and
# lays the parameters echoed out as 0.1 did (the selection's sections flattened back to their old
# keys, as NEW's `params --json` names them), so that a renamed parameter is not a difference.
normalise() {
  python3 -c '
import json, sys
renamed = [r for r in json.load(open(sys.argv[2]))["segmentation"] if r.get("old_key")]
def flatten(x):
    for r in renamed:
        *path, name = r["key"].split(".")
        where = x
        for p in path:
            where = where.get(p) if isinstance(where, dict) else None
        if isinstance(where, dict) and name in where:
            old_section, old_name = r["old_key"].rsplit(".", 1)
            x[old_section][old_name] = where.pop(name)
    for section in ("voxels", "image", "occlusion", "containers"):
        if isinstance(x["selection"].get(section), dict) and not x["selection"][section]:
            del x["selection"][section]
def strip(x):
    if isinstance(x, dict):
        if isinstance(x.get("selection"), dict):
            flatten(x)
        return {k: strip(v) for k, v in x.items()
                if not (k.endswith("_ms") or k in ("times_ms", "version", "commit", "build"))}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open(sys.argv[1]))), indent=1, sort_keys=True))' "$1" "$work/table.json"
}

# Both builds run in the same folder ($work/run, then renamed), so that the paths the reports
# name are the same.
run_all() {  # BIN OUT THREADS
  local bin=$1 final=$2 threads=$3 out=$work/run
  mkdir -p "$out"
  for f in "$data"/mosd/learn/*.pcd; do
    "$bin" segment "$f" -o "$out/$(basename "$f" .pcd)" --threads "$threads" >/dev/null 2>&1
  done
  local db=$out/ycb-db
  for name in 009_gelatin_box 025_mug 061_foam_brick; do
    "$bin" db add "$db" --name "$name" --xyz "$data/ycbv/models/$name/points.xyz" >/dev/null 2>&1
  done
  for c in "$frames"/*-color.png; do
    local k
    k=$(basename "$c" -color.png)
    "$bin" recognize --color "$c" --depth "$frames/$k-depth.png" --meta "$frames/$k-meta.json" \
      --db "$db" -o "$out/ycb-$k" --threads "$threads" >/dev/null 2>&1
  done
  mv "$out" "$final"
}

"$new" params segmentation --json > "$work/table.json"
status=0
for threads in 1 2; do
  run_all "$old" "$work/old-$threads" "$threads"
  run_all "$new" "$work/new-$threads" "$threads"
  n=0
  for f in "$work/old-$threads"/*.pcd "$work/old-$threads"/*.png; do
    g=$work/new-$threads/$(basename "$f")
    n=$((n + 1))
    cmp -s "$f" "$g" || { echo "differs ($threads threads): $(basename "$f")"; status=1; }
  done
  for f in "$work/old-$threads"/*.json; do
    g=$work/new-$threads/$(basename "$f")
    n=$((n + 1))
    if ! diff -q <(normalise "$f") <(normalise "$g") >/dev/null; then
      echo "differs ($threads threads): $(basename "$f")"
      status=1
    fi
  done
  echo "$threads thread(s): $n files compared"
done
[ $status -eq 0 ] && echo "same outputs"
exit $status
