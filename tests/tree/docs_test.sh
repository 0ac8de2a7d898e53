#!/usr/bin/env bash
# scripts/check-docs.py catches what it must: a dead link, a dead anchor, a docs page that no link
# from README.md reaches, a README over 120 lines; and passes a tree where all holds (links in
# code are text). Each case is a small tree in a temporary folder.
set -euo pipefail
check=${1:-$(cd "$(dirname "$0")/../.." && pwd)}/scripts/check-docs.py
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0

tree_of() {  # NAME: a tree whose README links docs/a.md, which links b.md#usage
  mkdir -p "$work/$1/docs"
  printf '# Top\n\nSee [a](docs/a.md) and `[not a link](nowhere.md)`.\n\n```\n[code](gone.md)\n```\n' \
    >"$work/$1/README.md"
  printf '# A\n\n[b, usage](b.md#usage), [top](../README.md#top)\n' >"$work/$1/docs/a.md"
  printf '# B\n\n## Usage\n' >"$work/$1/docs/b.md"
}
case_of() {  # NAME EXPECTED_EXIT EXPECTED_TEXT: runs the check on $work/NAME
  local got=0
  python3 "$check" "$work/$1" 2>"$work/$1.out" || got=$?
  if [[ $got != "$2" ]] || { [[ -n $3 ]] && ! grep -q -- "$3" "$work/$1.out"; }; then
    echo "docs_test: $1: exit $got (expected $2), output without '$3':" >&2
    cat "$work/$1.out" >&2
    fail=1
  fi
}

tree_of ok
case_of ok 0 ''
tree_of dead
printf '[gone](docs/gone.md)\n' >>"$work/dead/README.md"
case_of dead 1 'README.md:8: docs/gone.md: no such file'
tree_of anchor
printf '# A\n\n[b](b.md#install)\n' >"$work/anchor/docs/a.md"
case_of anchor 1 'no heading with the anchor #install'
tree_of orphan
printf '# C\n' >"$work/orphan/docs/c.md"
case_of orphan 1 "docs/c.md: not reachable from README.md"
tree_of long
seq 1 121 | sed 's/^/line /' >>"$work/long/README.md"
case_of long 1 'README.md: 128 lines'
exit $fail
