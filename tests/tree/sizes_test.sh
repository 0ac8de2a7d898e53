#!/usr/bin/env bash
# scripts/check-sizes.py catches what it must (CONTRIBUTING.md, "Layout"): a function over 80
# lines, a source file over 600, and lets a long function pass when a `// Long:` comment says
# why. Each case is a small tree in a temporary folder.
set -euo pipefail
check=${1:-$(cd "$(dirname "$0")/../.." && pwd)}/scripts/check-sizes.py
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0

function_of() {  # NAME LINES [COMMENT]: a C++ function of LINES lines in total
  [[ -n ${3:-} ]] && echo "$3"
  echo "int $1(int a,"
  echo "       int b) {"
  for ((i = 0; i < $2 - 4; ++i)); do echo "  a += b * $i;"; done
  echo "  return a;"
  echo "}"
}
case_of() {  # NAME EXPECTED_EXIT: runs the check on $work/NAME
  local got=0
  python3 "$check" "$work/$1" >"$work/$1.out" || got=$?
  if [[ $got != "$2" ]]; then
    echo "sizes_test: $1: exit $got, expected $2" >&2
    cat "$work/$1.out" >&2
    fail=1
  fi
}

mkdir -p "$work"/{ok,long,justified,big,app}/{src/core,apps}
function_of short 80 >"$work/ok/src/core/a.cpp"
case_of ok 0
function_of long 81 >"$work/long/src/core/a.cpp"
case_of long 1
grep -q "a.cpp:1: function of 81 lines" "$work/long.out" || { echo "sizes_test: no line named" >&2; fail=1; }
function_of long 120 "// Long: a table, one row per parameter." >"$work/justified/src/core/a.cpp"
case_of justified 0
for k in 1 2 3 4 5 6 7 8; do function_of "f$k" 76; done >"$work/big/src/core/a.cpp"  # 608 lines
case_of big 1
function_of run 90 >"$work/app/apps/main.cpp"
case_of app 1
exit $fail
