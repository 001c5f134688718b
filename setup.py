"""Builds the compiled part of the Python module (hexrefine._hexrefine) with CMake for pip.

pyproject.toml declares the package; this file only runs CMake: it configures a build folder
(Release, no tests, no benchmarks, this interpreter) under setuptools' build_temp, builds the
target _hexrefine and copies it where setuptools packs the extension. HEXREFINE_CMAKE_BUILD_DIR
names an existing, configured build folder to build in instead (its target is rebuilt only if
out of date: the install test uses it so as not to compile the library twice).
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


def project_version():
    """The version of CMakeLists.txt's project(), the one place it is written."""
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(hexrefine VERSION ([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("HEXREFINE_CMAKE_BUILD_DIR")
        if build:
            build = pathlib.Path(build).resolve()
        else:
            build = pathlib.Path(self.build_temp).resolve() / "cmake"
            subprocess.check_call(
                ["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                 "-DHEXREFINE_TESTS=OFF", "-DHEXREFINE_BENCHMARKS=OFF",
                 f"-DPython_EXECUTABLE={sys.executable}"])
        subprocess.check_call(["cmake", "--build", str(build), "--target", "_hexrefine", "-j",
                               str(os.cpu_count() or 2)])
        built = sorted((build / "experiments" / "python" / "hexrefine").glob("_hexrefine*.so"))
        if not built:
            sys.exit(f"setup.py: no _hexrefine*.so in {build}/experiments/python/hexrefine")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[0], target)


# setuptools' own build and egg-info folders go under build/ (ignored), not into the sources.
(ROOT / "build").mkdir(exist_ok=True)
setup(version=project_version(),
      ext_modules=[Extension("hexrefine._hexrefine", sources=[])],
      cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": "build/python-package"},
               "egg_info": {"egg_base": "build"}})
