#!/usr/bin/env bash
# The version is written once, in CMakeLists.txt's project() (CHANGELOG.md, "0.2.0"):
#   version_test.sh SOURCE_DIR VERSION PYTHON
# checks that VERSION (PROJECT_VERSION, as CMake read it) is what setup.py gives pip, that
# pyproject.toml types no version of its own, that CHANGELOG.md dates a release of it
# ("## VERSION (YYYY-MM-DD)", what the .debs' changelog is dated by), and that the example
# consumer asks find_package for this major.minor (SameMinorVersion: 0.x breaks at each minor).
set -euo pipefail
src=$1 version=$2 python=$3
fail() {
  echo "version: $*" >&2
  exit 1
}
pip_version=$(cd "$src" && "$python" setup.py --version 2>/dev/null | tail -n 1)
[ "$pip_version" = "$version" ] || fail "setup.py says '$pip_version', CMakeLists.txt $version"
if grep -nE '^version *=' "$src/pyproject.toml"; then
  fail "pyproject.toml types a version; it is dynamic (setup.py reads CMakeLists.txt)"
fi
grep -q '^dynamic = \["version"\]' "$src/pyproject.toml" || fail "pyproject.toml: no dynamic version"
grep -qE "^## ${version//./\\.} \([0-9]{4}-[0-9]{2}-[0-9]{2}\)$" "$src/CHANGELOG.md" ||
  fail "CHANGELOG.md has no dated section '## $version (YYYY-MM-DD)'"
minor=${version%.*}
grep -q "^find_package(proxseg ${minor//./\\.} " "$src/examples/CMakeLists.txt" ||
  fail "examples/CMakeLists.txt does not ask for proxseg $minor"
echo "version: $version in CMakeLists.txt, setup.py, CHANGELOG.md (dated) and examples/"
