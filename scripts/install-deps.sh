#!/usr/bin/env bash
# Installs proxseg's build dependencies from Debian 12's packages, only those that are missing.
# Works as root without a TTY (CI); uses sudo when run as a normal user.
# Usage: scripts/install-deps.sh [--bench|--fuzz]   (--bench adds PCL and OpenCV's contrib modules,
# the benchmarks' peers (surface_matching: the PPF recognition peer), and gnuplot, which draws the
# recognition benchmark's ROC and precision-recall curves; --fuzz adds clang and its runtimes for
# libFuzzer, `make fuzz`)
set -euo pipefail

# dpkg-dev: dpkg-shlibdeps, which `make package` uses to declare the .debs' dependencies;
# man-db reads the man page in the package test, lintian checks the .debs there. doxygen:
# `make docs` and proxseg-doc.
# The Python module: python3-dev, pybind11-dev and python3-numpy build it; pytest runs its tests;
# python3-open3d (Open3D interop), python3-matplotlib and python3-tqdm (the examples) are tested
# when present and installed here so that they are. python3-distributed and python3-dask run
# batches on a Dask cluster (python3 -m proxseg.dask, docs/batch.md). python3-mypy checks the
# type stubs and annotations; python3-venv, python3-pip and python3-setuptools `pip install .`.
# zlib1g-dev: the 3D page's points are deflated. chromium: the pages' tests load them in
# headless Chromium (python/tests/chromium.py drives it over its DevTools pipe).
packages=(cmake g++ make pkg-config libopen3d-dev libopencv-dev libeigen3-dev libboost-dev
  libcli11-dev nlohmann-json3-dev libgtest-dev libbenchmark-dev libpng-dev libjpeg-dev libsqlite3-dev
  zlib1g-dev dpkg-dev man-db lintian doxygen chromium
  python3-dev pybind11-dev python3-numpy python3-pytest python3-open3d python3-matplotlib
  python3-tqdm python3-distributed python3-dask python3-mypy python3-venv python3-pip
  python3-setuptools)
if [ "${1:-}" = "--bench" ]; then
  packages+=(libpcl-dev libopencv-contrib-dev gnuplot-nox)
fi
if [ "${1:-}" = "--fuzz" ]; then
  packages+=(clang-14 libclang-rt-14-dev libomp-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: not root and no sudo; install: ${missing[*]}" >&2; exit 1; }
  sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
