#!/usr/bin/env bash
# That check_layering.sh fails on each kind of wrong-way include: copies of the tree with one
# injected (a core header including io, io including eval or recognition, core including
# recognition, a core source including an io
# private file, a src/util helper including a proxseg header, the Python bindings including
# eval), each must be reported with its
# file, and the untouched copy must pass.
# Usage: tests/tree/layering_test.sh SOURCE_DIR
set -euo pipefail
src=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
check=$src/tests/tree/check_layering.sh

fresh() {
  rm -rf "$work/tree"
  mkdir -p "$work/tree"
  cp -r "$src/include" "$src/src" "$work/tree/"
  mkdir -p "$work/tree/python"
  cp -r "$src/python/src" "$work/tree/python/"
}

expect_fail() {  # FILE LINE-TO-ADD
  fresh
  sed -i "1a $2" "$work/tree/$1"
  if bash "$check" "$work/tree" 2>"$work/err"; then
    echo "FAIL: check_layering.sh accepted $2 in $1" >&2
    exit 1
  fi
  grep -q "^$1:2:" "$work/err" || { echo "FAIL: $1 not named:" >&2; cat "$work/err" >&2; exit 1; }
  echo "ok: $1 with $2 rejected"
}

fresh
bash "$check" "$work/tree"
expect_fail include/proxseg/core/frame.hpp '#include <proxseg/io/cloud_io.hpp>'
expect_fail include/proxseg/recognition/recognition.hpp '#include <proxseg/eval/metrics.hpp>'
expect_fail src/core/selection.cpp '#include <proxseg/eval/scene_eval.hpp>'
expect_fail include/proxseg/io/output.hpp '#include <proxseg/eval/rec_eval.hpp>'
expect_fail include/proxseg/io/output.hpp '#include <proxseg/recognition/registration.hpp>'
expect_fail src/core/pipeline.cpp '#include <proxseg/recognition/recognition.hpp>'
expect_fail src/core/features.cpp '#include "../io/formats/image_io.hpp"'
expect_fail src/recognition/icp.cpp '#include "io/formats/image_io.hpp"'
expect_fail src/util/stopwatch.hpp '#include <proxseg/core/frame.hpp>'
expect_fail src/util/stopwatch.hpp '#include "../core/maxflow.hpp"'
expect_fail python/src/segment.cpp '#include <proxseg/eval/metrics.hpp>'
echo "layering_test: all injected wrong-way includes were caught"
