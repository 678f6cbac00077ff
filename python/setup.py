# `pip install ./python` (docs/PYTHON.md): builds the module with the
# project's CMake build (target rastray_python, in build/ beside this folder
# or in $RASTRAY_BUILD_DIR; configured first if it does not exist) and
# packages what it made: rastray/__init__.py, the extension rastray._core and
# rastray_oiio.so (OpenImageIO, loaded on first use: the extension looks
# beside itself, common/oiio_module.cpp). Run pip with --no-build-isolation:
# the build uses the system's setuptools, CMake and compilers, nothing from PyPI.
import glob
import os
import shutil
import subprocess
import sys

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BUILD = os.path.abspath(os.environ.get("RASTRAY_BUILD_DIR", os.path.join(ROOT, "build")))
# setuptools' own scratch (build/lib, the egg-info) goes under the CMake
# build, not into the source tree.
SCRATCH = os.path.join(BUILD, "python", "setuptools")


class BinaryDistribution(Distribution):
    """A platform wheel: the package holds compiled code."""

    def has_ext_modules(self):
        return True


class BuildWithCMake(build_py):
    def run(self):
        build = BUILD
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            subprocess.check_call(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                                   "-DPython3_EXECUTABLE=" + os.path.realpath(sys.executable)])
        subprocess.check_call(["cmake", "--build", build, "--target", "rastray_python", "-j2"])
        made = os.path.join(build, "python", "rastray")
        extensions = glob.glob(os.path.join(made, "_core*.so"))
        if len(extensions) != 1:
            sys.exit(f"{made}: expected one _core*.so, found {extensions or 'none'} "
                     "(python/CMakeLists.txt says why the module was not built)")
        target = os.path.join(self.build_lib, "rastray")
        os.makedirs(target, exist_ok=True)
        for path in [os.path.join(made, "__init__.py"), extensions[0], os.path.join(build, "rastray_oiio.so")]:
            shutil.copy2(path, target)


os.makedirs(SCRATCH, exist_ok=True)
setup(
    name="rastray",
    version="0.1",
    description="One glTF scene, two renderers (z-buffer rasterizer, Embree ray caster), and where they differ",
    python_requires=">=3.8",
    packages=["rastray"],  # python/rastray; build_py below puts the built files beside it
    distclass=BinaryDistribution,
    cmdclass={"build_py": BuildWithCMake},
    zip_safe=False,
    options={"build": {"build_base": SCRATCH}, "egg_info": {"egg_base": SCRATCH}},
)
