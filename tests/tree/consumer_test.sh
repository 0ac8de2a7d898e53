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
#     the commit; and that no installed program loads Open3D and proxseg runs `recognize` (through
#     libexec/proxseg/proxseg-tools);
#   consumer_test.sh python PREFIX PYTHON_DIR PYTHON SCENE.pcd
#     imports the installed Python module (PYTHONPATH=PREFIX/PYTHON_DIR), checks that it and the
#     libraries it loads come from PREFIX, shows help(proxseg.segment), and segments the scene
#     with the labels of the installed CLI;
#   consumer_test.sh deb BUILD_DIR PYTHON SOURCE_DIR SCENE.pcd
#     makes the .debs (cpack: libproxseg0, libproxseg-dev, proxseg, python3-proxseg) into a
#     temporary directory, checks their names, dependencies and that no two hold one file,
#     installs them side by side with dpkg into a root of their own, and uses that root as a
#     user would: the C++ consumer with find_package and with pkg-config, the CLI, its man
#     page and completion, and `import proxseg`.
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
    build=$2 python=$3 src=$4 scene=$5
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
    (cd "$build" && cpack -G DEB -B "$work/package" >"$work/cpack.log" 2>&1) ||
      { cat "$work/cpack.log" >&2; exit 1; }
    if grep -i "warning" "$work/cpack.log"; then
      echo "consumer: cpack warned" >&2
      exit 1
    fi
    debs=()
    for p in libproxseg0 libproxseg-dev proxseg python3-proxseg; do
      deb=$(find "$work/package" -maxdepth 1 -name "${p}_*.deb")
      [ -n "$deb" ] || { echo "consumer: no $p package" >&2; exit 1; }
      debs+=("$deb")
    done
    dpkg-deb -f "$work/package"/libproxseg-dev_*.deb Depends | grep -q 'libproxseg0 (= '
    dpkg-deb -f "$work/package"/proxseg_*.deb Depends | grep -q 'libproxseg0 (= '
    dpkg-deb -f "$work/package"/python3-proxseg_*.deb Depends | grep -q python3-numpy
    dpkg-deb --ctrl-tarfile "$work/package"/libproxseg0_*.deb | tar -xO ./shlibs |
      grep -q '^libproxseg_core 0.1 libproxseg0'
    # No file in two packages (dpkg would refuse the second).
    for deb in "${debs[@]}"; do dpkg-deb -c "$deb" | awk '$1 !~ /^d/ {print $6}'; done |
      sort | uniq -d >"$work/shared-files"
    if [ -s "$work/shared-files" ]; then
      echo "consumer: files in two packages:" >&2
      cat "$work/shared-files" >&2
      exit 1
    fi
    # dpkg installs them into a root of its own (its own database); the system's packages
    # (Open3D, OpenCV, numpy) satisfy the rest outside it.
    root=$work/root
    mkdir -p "$root/var/lib/dpkg/info" "$root/var/lib/dpkg/updates"
    touch "$root/var/lib/dpkg/status"
    dpkg --root="$root" --log=/dev/null --force-depends --force-script-chrootless \
      --force-not-root -i "${debs[@]}" >"$work/dpkg.log" 2>&1 ||
      { cat "$work/dpkg.log" >&2; exit 1; }
    [ "$(dpkg --root="$root" -l | grep -c '^ii')" -eq 4 ]
    usr=$root/usr
    bash "$0" cmake "$usr" "$src" "$scene"
    bash "$0" pkg-config "$usr" "$src" "$scene"
    man -l "$usr/share/man/man1/proxseg.1.gz" 2>/dev/null | grep -q -- "--voxel-size"
    bash -c "source $usr/share/bash-completion/completions/proxseg;
      COMP_WORDS=(proxseg seg); COMP_CWORD=1; _proxseg; [[ \${COMPREPLY[*]} == *segment* ]]"
    pydir=$(dirname "$(find "$usr" -name '__init__.py' -path '*/proxseg/*')")
    PYTHONPATH=$(dirname "$pydir") "$python" -c "import proxseg; help(proxseg.segment)" \
      >"$work/help.txt"
    grep -q "segment(frame" "$work/help.txt"
    PYTHONPATH=$(dirname "$pydir") "$python" - "$root" <<'PY'
import sys
import proxseg
root = sys.argv[1]
libs = {l.split()[-1] for l in open("/proc/self/maps") if "libproxseg_" in l}
assert libs and all(l.startswith(root) for l in libs), libs
print(f"consumer: the .debs' module imports from {proxseg.__file__} with its own libraries")
PY
    echo "consumer (deb): 4 packages installed side by side; C++, CLI, man page, Python work"
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
    $(pkg-config --cflags --libs proxseg) $(pkg-config --variable=rpath proxseg)
  exe=$work/segment_scene
fi
# Runs from the prefix as built: find_package's imported targets and pkg-config's rpath variable
# point the program at the prefix's libraries (README, Library).
LD_LIBRARY_PATH= "$exe" "$scene" "$work/consumer"
# The installed CLI finds the installed libraries through its RPATH, without LD_LIBRARY_PATH.
"$prefix/bin/proxseg" segment "$scene" -o "$work/cli" 2>/dev/null
cmp "$work/consumer.pcd" "$work/cli.pcd"
# No installed program loads Open3D (0.1 s of CPU per process: docs/architecture.md); the
# segmenting one runs the installed proxseg-tools for the rest.
for program in "$prefix/bin/proxseg" "$prefix"/libexec/proxseg/proxseg-tools; do
  if ldd "$program" | grep -i open3d; then
    echo "consumer: the installed $program loads Open3D" >&2
    exit 1
  fi
done
"$prefix/bin/proxseg" recognize --help >"$work/recognize-help.txt"
grep -q -- "--db" "$work/recognize-help.txt"
cmp "$work/consumer.png" "$work/cli.png"
grep -q '"version"' "$work/consumer.json"
grep -q '"commit"' "$work/consumer.json"
echo "consumer ($mode): the same labelled PCD and picture as the installed CLI"
