"""Builds the extension proxseg._proxseg with CMake for `pip install .` (pyproject.toml): the
proxseg libraries static, so that the module is the package's only compiled file and needs no
library path; Open3D, OpenCV and the rest from the system, as the CMake build finds them."""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def version() -> str:
    """The project's version, written once: in CMakeLists.txt's project() (pyproject.toml lists
    the version as dynamic)."""
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    m = re.search(r"^project\(proxseg VERSION (\d+\.\d+\.\d+)\b", text, re.MULTILINE)
    if m is None:
        sys.exit("setup.py: no project(proxseg VERSION x.y.z) in CMakeLists.txt")
    return m.group(1)


class CMakeExtension(Extension):
    def __init__(self, name: str) -> None:
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext: Extension) -> None:
        build = Path(self.build_temp).resolve() / "cmake"
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                        "-DPROXSEG_SHARED=OFF", "-DCMAKE_POSITION_INDEPENDENT_CODE=ON",
                        "-DPROXSEG_BUILD_TESTS=OFF",
                        "-DPROXSEG_BUILD_BENCH=OFF",
                        f"-DPython3_EXECUTABLE={sys.executable}"], check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "_proxseg", "-j", jobs],
                       check=True)
        built = next((build / "python" / "proxseg").glob("_proxseg*.so"))
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, target)


setup(version=version(), ext_modules=[CMakeExtension("proxseg._proxseg")],
      cmdclass={"build_ext": CMakeBuild})
