"""The geomint module for pip (pyproject.toml): build_ext builds the _geomint target with the project's own CMake
build and puts it into the wheel next to python/geomint/__init__.py.

    GEOMINT_BUILD_DIR=build pip install --no-build-isolation --no-index .   # an existing build: nothing recompiles
    pip install --no-build-isolation --no-index .                           # its own build in build-pip/cmake

Without GEOMINT_BUILD_DIR the build is configured in build-pip/ (reused by the next install; CMAKE_ARGS adds options,
e.g. CMAKE_ARGS=-DCMAKE_CXX_COMPILER_LAUNCHER=ccache) and only the module's target is built (the libraries under
it, not the programs or the tests).
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.errors import SetupError  # reported as "error: ..." without a traceback

ROOT = os.path.dirname(os.path.abspath(__file__))
# setuptools' own files (the egg-info, the wheel's staging) in the build, not in the source tree, and not in build/,
# which is the CMake build `make` makes
WORK = os.path.join(os.path.abspath(os.environ["GEOMINT_BUILD_DIR"]), "pip") if os.environ.get("GEOMINT_BUILD_DIR") \
    else os.path.join(ROOT, "build-pip")


def project_version():
    """The version of CMakeLists.txt's project(), the one the C++ package carries."""
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(geomint VERSION ([0-9.]+)", f.read())
    if not match:
        raise SetupError("setup.py: no 'project(geomint VERSION x.y' in CMakeLists.txt")
    return match.group(1)


def run(command, what):
    print("geomint:", " ".join(shlex.quote(c) for c in command), flush=True)
    try:
        subprocess.run(command, check=True)
    except FileNotFoundError as e:
        raise SetupError(f"setup.py: {what}: {e.filename} not found (Debian: apt-get install cmake)") from e
    except subprocess.CalledProcessError as e:
        raise SetupError(f"setup.py: {what} failed (exit {e.returncode}); its output is above") from e


def is_geomint_build(build_dir):
    try:
        with open(os.path.join(build_dir, "CMakeCache.txt"), encoding="utf-8") as f:
            return "CMAKE_PROJECT_NAME:STATIC=geomint\n" in f.read()
    except OSError:
        return False


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build_dir = os.environ.get("GEOMINT_BUILD_DIR")
        if build_dir:
            build_dir = os.path.abspath(build_dir)
            if not is_geomint_build(build_dir):
                raise SetupError(f"setup.py: GEOMINT_BUILD_DIR={build_dir} is not a configured CMake build of "
                                 "geomint (no CMakeCache.txt of project geomint): configure it first (make build) "
                                 "or leave GEOMINT_BUILD_DIR unset")
        else:
            build_dir = os.path.join(WORK, "cmake")
            # the interpreter pip runs is the module's (its version and ABI); Release as `make` builds
            run(["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                 f"-DGEOMINT_PYTHON={sys.executable}"] + shlex.split(os.environ.get("CMAKE_ARGS", "")),
                "configuring the CMake build")
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        # up to date in an existing build: CMake checks and compiles nothing
        run(["cmake", "--build", build_dir, "--target", "_geomint", "-j", jobs], "building the module")

        # the module the build made, for this interpreter (a build configured for another Python has another name)
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        module = os.path.join(build_dir, "python", "geomint", "_geomint" + suffix)
        if not os.path.isfile(module):
            found = sorted(os.listdir(os.path.dirname(module))) if os.path.isdir(os.path.dirname(module)) else []
            raise SetupError(f"setup.py: no {module} after the build (found: {', '.join(found) or 'nothing'}): "
                               f"the build's Python (GEOMINT_PYTHON in its CMakeCache.txt) is not {sys.executable}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copy2(module, target)


os.makedirs(WORK, exist_ok=True)
setup(
    version=project_version(),
    packages=["geomint"],
    package_dir={"geomint": "python/geomint"},
    ext_modules=[Extension("geomint._geomint", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": os.path.join(WORK, "setuptools")}, "egg_info": {"egg_base": WORK}},
)
