#!/usr/bin/env bash
# Uses proxseg as a user does (README, Library).
#   consumer_test.sh install BUILD_DIR PREFIX
#     installs the build tree into PREFIX (emptied first);
#   consumer_test.sh headers PREFIX
#     compiles every installed header on its own, and checks that core's name no third-party
#     library but Eigen (README, Library: io and eval add nlohmann-json);
#   consumer_test.sh cmake|pkg-config PREFIX SOURCE_DIR SCENE.pcd
#     builds examples/segment_scene.cpp against the installed files only, with
#     find_package(proxseg 0.x REQUIRED COMPONENTS io) or with pkg-config, runs it on a real
#     scene, and checks that it writes the same labelled PCD and picture as the installed CLI and
#     a report with the version and the commit; and that no installed program loads Open3D and
#     proxseg runs `recognize` (through libexec/proxseg/proxseg-tools). cmake also asks
#     find_package for components: found ones build and link their targets, a missing one fails
#     naming it, the reason and the components there are (REQUIRED) or leaves proxseg_FOUND false
#     with proxseg_NOT_FOUND_MESSAGE (without REQUIRED);
#   consumer_test.sh python PREFIX PYTHON_DIR PYTHON SCENE.pcd
#     imports the installed Python module (PYTHONPATH=PREFIX/PYTHON_DIR), checks that it and the
#     libraries it loads come from PREFIX, shows help(proxseg.segment), and segments the scene
#     with the labels of the installed CLI;
#   consumer_test.sh deb BUILD_DIR PYTHON SOURCE_DIR SCENE.pcd
#     builds the API references (target proxseg_docs), makes the .debs (cpack: one per library,
#     libproxseg-core0.2 ..., libproxseg-dev, proxseg, python3-proxseg, proxseg-doc) into a
#     temporary directory, checks their names, dependencies (none on Open3D), shlibs, that no two
#     hold one file and that lintian finds no error in them (its warnings are printed), installs
#     them side by side with dpkg into a root of their own, and uses that root as a user would:
#     the C++ consumer with find_package (components too) and with pkg-config, the CLI, its man
#     page and completion, `import proxseg`, the documentation.
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
    cmake --build "$build" --target proxseg_docs >"$work/docs.log" 2>&1 ||
      { cat "$work/docs.log" >&2; exit 1; }
    (cd "$build" && cpack -G DEB -B "$work/package" >"$work/cpack.log" 2>&1) ||
      { cat "$work/cpack.log" >&2; exit 1; }
    if grep -i "warning" "$work/cpack.log"; then
      echo "consumer: cpack warned" >&2
      exit 1
    fi
    # The SONAMEs' version (0.x: major.minor) names the library packages.
    so=$(sed -n 's/^project(proxseg VERSION \([0-9]*\.[0-9]*\).*/\1/p' "$src/CMakeLists.txt")
    libs=(core io recognition eval)
    packages=()
    for part in "${libs[@]}"; do packages+=("libproxseg-$part$so"); done
    packages+=(libproxseg-dev proxseg python3-proxseg proxseg-doc)
    debs=()
    for p in "${packages[@]}"; do
      deb=$(find "$work/package" -maxdepth 1 -name "${p}_*.deb")
      [ -n "$deb" ] || { echo "consumer: no $p package" >&2; exit 1; }
      debs+=("$deb")
    done
    [ "$(find "$work/package" -maxdepth 1 -name '*.deb' | wc -l)" -eq "${#packages[@]}" ] ||
      { echo "consumer: other packages than ${packages[*]}" >&2; exit 1; }
    field() { dpkg-deb -f "$work/package/$1"_*.deb "$2"; }
    for part in "${libs[@]}"; do
      # Each library package declares its SONAME for the packages built against it.
      dpkg-deb --ctrl-tarfile "$work/package/libproxseg-$part${so}"_*.deb | tar -xO ./shlibs |
        grep -q "^libproxseg_$part $so libproxseg-$part$so (>= "
      field libproxseg-dev Depends | grep -q "libproxseg-$part$so (= "
      field proxseg Depends | grep -q "libproxseg-$part$so (= "
    done
    # The layering in the dependencies: io needs core, not recognition's SQLite or OpenMP.
    field "libproxseg-io$so" Depends | grep -q "libproxseg-core$so (= "
    if field "libproxseg-io$so" Depends | grep -E 'libsqlite|libgomp|recognition|eval'; then
      echo "consumer: libproxseg-io$so depends on more than it links" >&2
      exit 1
    fi
    field python3-proxseg Depends | grep -q python3-numpy
    [ "$(field proxseg-doc Architecture)" = all ]
    for deb in "${debs[@]}"; do
      if dpkg-deb -f "$deb" Depends | grep -i open3d; then
        echo "consumer: $(basename "$deb") depends on Open3D" >&2
        exit 1
      fi
    done
    # No file in two packages (dpkg would refuse the second).
    for deb in "${debs[@]}"; do dpkg-deb -c "$deb" | awk '$1 !~ /^d/ {print $6}'; done |
      sort | uniq -d >"$work/shared-files"
    if [ -s "$work/shared-files" ]; then
      echo "consumer: files in two packages:" >&2
      cat "$work/shared-files" >&2
      exit 1
    fi
    # Debian's checks: no error; the warnings are printed (the report lists why each stays).
    # (exit status 1: an error; 2 and more: lintian itself failed)
    status=0
    lintian --fail-on error --no-tag-display-limit "${debs[@]}" >"$work/lintian.log" 2>&1 ||
      status=$?
    grep -E '^W: ' "$work/lintian.log" || true
    if [ "$status" -ne 0 ]; then
      echo "consumer: lintian exit status $status:" >&2
      cat "$work/lintian.log" >&2
      exit 1
    fi
    # dpkg installs them into a root of its own (its own database); the system's packages
    # (OpenCV, numpy, ...) satisfy the rest outside it.
    root=$work/root
    mkdir -p "$root/var/lib/dpkg/info" "$root/var/lib/dpkg/updates"
    touch "$root/var/lib/dpkg/status"
    dpkg --root="$root" --log=/dev/null --force-depends --force-script-chrootless \
      --force-not-root -i "${debs[@]}" >"$work/dpkg.log" 2>&1 ||
      { cat "$work/dpkg.log" >&2; exit 1; }
    [ "$(dpkg --root="$root" -l | grep -c '^ii')" -eq "${#packages[@]}" ]
    usr=$root/usr
    # Debian's places: the multiarch library folder, python3's dist-packages, the copyright.
    triplet=$(dpkg-architecture -qDEB_HOST_MULTIARCH)
    for part in "${libs[@]}"; do
      [ -f "$usr/lib/$triplet/libproxseg_$part.so.$so" ]
      [ -L "$usr/lib/$triplet/libproxseg_$part.so" ]
    done
    for p in "${packages[@]}"; do
      grep -q '^License: BSD-3-Clause' "$usr/share/doc/$p/copyright"
    done
    bash "$0" cmake "$usr" "$src" "$scene"
    bash "$0" pkg-config "$usr" "$src" "$scene"
    man -l "$usr/share/man/man1/proxseg.1.gz" 2>/dev/null >"$work/man.txt"
    grep -q -- "--voxel-size" "$work/man.txt"
    grep -q "/usr/share/doc/proxseg-doc" "$work/man.txt"
    "$usr/bin/proxseg" --help | grep -q "/usr/share/doc/proxseg-doc"
    bash -c "source $usr/share/bash-completion/completions/proxseg;
      COMP_WORDS=(proxseg seg); COMP_CWORD=1; _proxseg; [[ \${COMPREPLY[*]} == *segment* ]]"
    # What the man page and --help point at is there.
    doc=$usr/share/doc/proxseg-doc
    for f in parameters.md batch.md database.md method.md metrics.md clutter.md changelog.gz \
      img/rec-roc.png api/cpp/index.html api/python/proxseg.html; do
      [ -s "$doc/$f" ] || { echo "consumer: proxseg-doc lacks $f" >&2; exit 1; }
    done
    # The installed README's links to the pages resolve beside it.
    for f in $(grep -o '](\(img/\)\?[a-z_-]*\.\(md\|png\))' "$doc/README.md" | tr -d '()]'); do
      [ -s "$doc/$f" ] || { echo "consumer: proxseg-doc's README links $f, not there" >&2; exit 1; }
    done
    grep -q '](cli.md)' "$doc/README.md"
    pydir=$usr/lib/python3/dist-packages
    [ -f "$pydir/proxseg/__init__.py" ]
    PYTHONPATH=$pydir "$python" -c "import proxseg; help(proxseg.segment)" >"$work/help.txt"
    grep -q "segment(frame" "$work/help.txt"
    PYTHONPATH=$pydir "$python" - "$root" <<'PY'
import sys
import proxseg
root = sys.argv[1]
libs = {l.split()[-1] for l in open("/proc/self/maps") if "libproxseg_" in l}
assert libs and all(l.startswith(root) for l in libs), libs
print(f"consumer: the .debs' module imports from {proxseg.__file__} with its own libraries")
PY
    echo "consumer (deb): ${#packages[@]} packages (${packages[*]}) pass lintian without" \
      "errors and installed side by side; C++ (components too), CLI, man page, Python, docs work"
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
# find_package(proxseg [REQUIRED] COMPONENTS $1 [OPTIONAL_COMPONENTS $2]) in a project of its own
# (its output in $work/components.log): the components' targets linked into a program, which runs.
components() {
  local dir=$work/components
  rm -rf "$dir" && mkdir -p "$dir"
  cat >"$dir/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.16)
project(proxseg_components LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 17)
if(REQUIRED)
  find_package(proxseg REQUIRED COMPONENTS ${ASK} OPTIONAL_COMPONENTS ${OPTIONAL})
else()
  find_package(proxseg COMPONENTS ${ASK} OPTIONAL_COMPONENTS ${OPTIONAL})
endif()
message(STATUS "proxseg_FOUND=${proxseg_FOUND}")
foreach(c ${ASK} ${OPTIONAL})
  message(STATUS "proxseg_${c}_FOUND=${proxseg_${c}_FOUND}")
endforeach()
message(STATUS "proxseg_NOT_FOUND_MESSAGE=${proxseg_NOT_FOUND_MESSAGE}")
if(proxseg_FOUND)
  file(WRITE ${CMAKE_BINARY_DIR}/main.cpp "#include <string>\n#include <proxseg/core/version.hpp>
int main() { return proxseg::version() == std::string(PROXSEG_VERSION) ? 0 : 1; }\n")
  add_executable(main ${CMAKE_BINARY_DIR}/main.cpp)
  foreach(c ${ASK})
    target_link_libraries(main PRIVATE proxseg::${c})
  endforeach()
endif()
CMAKE
  cmake -S "$dir" -B "$dir/build" -DCMAKE_PREFIX_PATH="$prefix" "-DASK=$1" "-DOPTIONAL=${2:-}" \
    "-DREQUIRED=${3:-ON}" >"$work/components.log" 2>&1
}
# expect REGEX: the last find_package run said it (or the test fails showing what it said).
expect() {
  grep -qE "$1" "$work/components.log" ||
    { echo "consumer: expected /$1/ from find_package:" >&2; cat "$work/components.log" >&2; exit 1; }
}
if [ "$mode" = cmake ]; then
  cmake -S "$src/examples" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$work/build" >/dev/null
  exe=$work/build/segment_scene
  # Found: each component's target, linked and run (core alone; recognition and eval).
  for ask in "core" "recognition;eval" "proxseg"; do
    components "$ask" || { cat "$work/components.log" >&2; exit 1; }
    cmake --build "$work/components/build" >/dev/null
    LD_LIBRARY_PATH= "$work/components/build/main"
    for c in ${ask//;/ }; do expect "proxseg_${c}_FOUND=(1|TRUE)$"; done
  done
  # A missing one that is REQUIRED: find_package stops, naming it, why, and what there is.
  if components "io;nosuch"; then
    echo "consumer: find_package(proxseg REQUIRED COMPONENTS io nosuch) succeeded" >&2
    exit 1
  fi
  expect "nosuch: not a component of proxseg"
  expect "the components are core, io, recognition, eval, proxseg"
  # Without REQUIRED it returns with proxseg_FOUND false and the reason; a missing optional
  # component is no failure.
  components "io;nosuch" "" OFF || { cat "$work/components.log" >&2; exit 1; }
  expect "proxseg_FOUND=(0|FALSE)$"
  expect "proxseg_io_FOUND=(1|TRUE)$"
  expect "proxseg_nosuch_FOUND=(0|FALSE)$"
  expect "proxseg_NOT_FOUND_MESSAGE=proxseg [0-9.]+ in .* lacks required components:$"
  expect "^  nosuch: not a component of proxseg$"
  components io nosuch || { cat "$work/components.log" >&2; exit 1; }
  expect "proxseg_FOUND=(1|TRUE)$"
  expect "proxseg_nosuch_FOUND=(0|FALSE)$"
  echo "consumer (cmake): components core, io, recognition, eval, proxseg found and linked;" \
    "a missing one named with its reason"
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
