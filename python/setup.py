# pip install for pyrcb4, with Debian's setuptools and no download:
#   python3 -m venv --system-site-packages venv && venv/bin/pip install --no-build-isolation --no-index ./python
# The extension is the project's own CMake build (target pyrcb4_core, Release) for this interpreter.
# SPDX-License-Identifier: BSL-1.0
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent.parent
VERSION = re.search(r"project\(rcb4 VERSION (\d+\.\d+\.\d+)", (ROOT / "CMakeLists.txt").read_text()).group(1)


class CMakeBuild(build_ext):
    """Builds pyrcb4._core with CMake instead of compiling sources itself."""

    def build_extension(self, ext):
        build = Path(self.build_temp).resolve() / "cmake"
        # Ninja when it is there (cmake/install-deps.sh installs it; make may not be on the machine);
        # a build folder left by another generator (an earlier try without Ninja) is made anew.
        generator = []
        if shutil.which("ninja"):
            generator = ["-G", "Ninja"]
            cache = build / "CMakeCache.txt"
            if cache.exists() and "CMAKE_GENERATOR:INTERNAL=Ninja\n" not in cache.read_text(errors="replace"):
                shutil.rmtree(build)
        subprocess.run(["cmake", *generator, "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                        f"-DPython_EXECUTABLE={sys.executable}", "-DRCB4_BUILD_TESTS=OFF",
                        "-DRCB4_BUILD_EXAMPLES=OFF", "-DRCB4_BUILD_TOOLS=OFF", "-DRCB4_BUILD_BENCHMARKS=OFF", "-DRCB4_INSTALL=OFF"],
                       check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "pyrcb4_core", "--parallel",
                        str(os.cpu_count() or 1)], check=True)
        built = next((build / "python" / "pyrcb4").glob("_core*.so"))
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, target)


setup(
    name="pyrcb4",
    version=VERSION,
    description="rcb4 for Python: KONDO's RCB-4 robot controller over its serial line",
    license="BSL-1.0",
    packages=["pyrcb4"],
    package_data={"pyrcb4": ["__init__.pyi", "py.typed"]},
    ext_modules=[Extension("pyrcb4._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.8",
)
