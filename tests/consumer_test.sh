#!/usr/bin/env bash
# Uses proxseg as a user does (README, Library).
#   consumer_test.sh install BUILD_DIR PREFIX
#     installs the build tree into PREFIX (emptied first);
#   consumer_test.sh headers PREFIX
#     compiles every installed header on its own, and checks that core's name no third-party
#     library but Eigen (README, Library: io and eval add nlohmann-json);
#   consumer_test.sh cmake|pkg-config PREFIX SOURCE_DIR SCENE.pcd
#     builds examples/segment_scene.cpp against the installed files only, with
#     find_package(proxseg) or with pkg-config, runs it on a real scene, and checks that it writes
#     the same labelled PCD and picture as the installed CLI and a report with the version and
#     the commit; and that the installed proxseg loads no Open3D yet runs `recognize` (through
#     libexec/proxseg/proxseg-tools);
#   consumer_test.sh python PREFIX PYTHON_DIR PYTHON SCENE.pcd
#     imports the installed Python module (PYTHONPATH=PREFIX/PYTHON_DIR), checks that it and the
#     libraries it loads come from PREFIX, shows help(proxseg.segment), and segments the scene
#     with the labels of the installed CLI;
#   consumer_test.sh deb BUILD_DIR PYTHON
#     makes the .deb (cpack) into a temporary directory, unpacks it, and imports the module from
#     the unpacked usr/ (libraries found through the module's relative RPATH).
set -euo pipefail
mode=${1:-}
case $mode in
  install)
    build=$2 prefix=$3
    rm -rf "$prefix"
    cmake --install "$build" --prefix "$prefix" >/dev/null
    echo "consumer: installed into $prefix"
    exit 0
    ;;
  headers)
    prefix=$2
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
    eigen=$(pkg-config --cflags eigen3)
    count=0
    for h in $(cd "$prefix/include" && find proxseg -name '*.hpp' | sort); do
      echo "#include <$h>" >"$work/one.cpp"
      # shellcheck disable=SC2086  # the flags are separate words
      g++ -std=c++17 -fsyntax-only -I"$prefix/include" $eigen "$work/one.cpp"
      count=$((count + 1))
    done
    if grep -E '^#include <' "$prefix"/include/proxseg/core/*.hpp |
      grep -vE '<(proxseg/core/|Eigen/)|<[a-z_]+>'; then
      echo "consumer: core headers may include only core, Eigen and standard headers" >&2
      exit 1
    fi
    echo "consumer: $count installed headers compile on their own (core with Eigen only)"
    exit 0
    ;;
  python)
    prefix=$2 pydir=$3 python=$4 scene=$5
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
    PYTHONPATH=$prefix/$pydir "$python" -c "import proxseg; help(proxseg.segment)" >"$work/help.txt"
    grep -q "segment(frame" "$work/help.txt"
    LD_LIBRARY_PATH= "$prefix/bin/proxseg" segment "$scene" -o "$work/cli" >/dev/null 2>&1
    PYTHONPATH=$prefix/$pydir "$python" - "$prefix" "$scene" "$work/cli.pcd" <<'PY'
import sys
import numpy as np
import proxseg
prefix, scene, cli = sys.argv[1:]
assert proxseg.__file__.startswith(prefix), proxseg.__file__
libs = {l.split()[-1] for l in open("/proc/self/maps") if "libproxseg_" in l}
assert libs and all(l.startswith(prefix) for l in libs), libs
result = proxseg.segment(proxseg.read_point_cloud(scene))
assert np.array_equal(result.labels, proxseg.read_point_cloud(cli).label)
print(f"consumer: import proxseg {proxseg.__version__} from {prefix} ({len(libs)} libraries "
      f"there); labels equal the installed CLI's")
PY
    exit 0
    ;;
  deb)
    build=$2 python=$3
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
    (cd "$build" && cpack -G DEB -B "$work/package" >/dev/null)
    deb=$(find "$work/package" -maxdepth 1 -name 'proxseg_*.deb')
    dpkg-deb -x "$deb" "$work/root"
    dpkg-deb -f "$deb" Depends | grep -q python3-numpy
    pydir=$(dirname "$(find "$work/root" -name '__init__.py' -path '*/proxseg/*')")
    PYTHONPATH=$(dirname "$pydir") "$python" -c "import proxseg; help(proxseg.segment)" \
      >"$work/help.txt"
    grep -q "segment(frame" "$work/help.txt"
    PYTHONPATH=$(dirname "$pydir") "$python" - "$work/root" <<'PY'
import sys
import proxseg
root = sys.argv[1]
libs = {l.split()[-1] for l in open("/proc/self/maps") if "libproxseg_" in l}
assert libs and all(l.startswith(root) for l in libs), libs
print(f"consumer: the .deb's module imports from {proxseg.__file__} with its own libraries")
PY
    exit 0
    ;;
  cmake | pkg-config) prefix=$2 src=$3 scene=$4 ;;
  *)
    echo "consumer_test.sh: expected install, headers, cmake, pkg-config, python or deb, got '$mode'" >&2
    exit 2
    ;;
esac
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ "$mode" = cmake ]; then
  cmake -S "$src/examples" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$work/build" >/dev/null
  exe=$work/build/segment_scene
else
  PKG_CONFIG_PATH=$(dirname "$(find "$prefix" -name proxseg.pc)")
  export PKG_CONFIG_PATH
  # shellcheck disable=SC2046  # the flags are separate words
  g++ -std=c++17 -O2 "$src/examples/segment_scene.cpp" -o "$work/segment_scene" \
    $(pkg-config --cflags --libs proxseg)
  exe=$work/segment_scene
fi
libdir=$(dirname "$(find "$prefix" -name 'libproxseg_core.so.*' | head -n 1)")
LD_LIBRARY_PATH=$libdir "$exe" "$scene" "$work/consumer"
# The installed CLI finds the installed libraries through its RPATH, without LD_LIBRARY_PATH.
"$prefix/bin/proxseg" segment "$scene" -o "$work/cli" 2>/dev/null
cmp "$work/consumer.pcd" "$work/cli.pcd"
# The segmenting program loads no Open3D; it runs the installed proxseg-tools for the rest.
if ldd "$prefix/bin/proxseg" | grep -i open3d; then
  echo "consumer: the installed proxseg loads Open3D" >&2
  exit 1
fi
"$prefix/bin/proxseg" recognize --help >"$work/recognize-help.txt"
grep -q -- "--db" "$work/recognize-help.txt"
cmp "$work/consumer.png" "$work/cli.png"
grep -q '"version"' "$work/consumer.json"
grep -q '"commit"' "$work/consumer.json"
echo "consumer ($mode): the same labelled PCD and picture as the installed CLI"
