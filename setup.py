"""Builds lamina's compiled module `lamina._lamina` with CMake for `pip install .`.

pyproject.toml holds the package's metadata; this file only tells setuptools how the extension is
built: CMake configures the repository in setuptools' build folder (Release, the Python module on,
for the interpreter running pip) and builds the target `lamina_python`, whose library is copied
where setuptools packs it. LAMINA_CMAKE_BUILD_DIR names an already configured build folder to
build the target in instead (the test `pip_install` uses the tree it tests). CMAKE_BUILD_PARALLEL_LEVEL
sets the jobs (default 2); CMAKE_ARGS adds configure options (space-separated, e.g.
-DCMAKE_CXX_COMPILER_LAUNCHER=ccache).
"""

import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        root = Path(__file__).resolve().parent
        given = os.environ.get("LAMINA_CMAKE_BUILD_DIR")
        build = Path(given) if given else Path(self.build_temp).resolve() / "cmake"
        if not given:
            subprocess.run(["cmake", "-S", str(root), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                            "-DLAMINA_PYTHON=ON", f"-DPython3_EXECUTABLE={sys.executable}",
                            *os.environ.get("CMAKE_ARGS", "").split()], check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        subprocess.run(["cmake", "--build", str(build), "--target", "lamina_python", "-j", jobs],
                       check=True)
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = build / "python" / "lamina" / f"_lamina{suffix}"
        if not built.exists():
            raise RuntimeError(f"{built}: not built (is {build} configured for this Python?)")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, target)


# setuptools' own build folder and metadata go to build-pip/ (git-ignored), not to build/, which
# is CMake's, nor beside the sources.
Path(__file__).resolve().parent.joinpath("build-pip").mkdir(exist_ok=True)
setup(ext_modules=[CMakeExtension("lamina._lamina")], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": "build-pip"}, "egg_info": {"egg_base": "build-pip"}})
