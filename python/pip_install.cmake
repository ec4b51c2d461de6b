# `pip install .` as README shows it, tested: a fresh virtual environment (Debian's python3 -m venv
# --system-site-packages), the module installed from this source tree with the build's own module
# (GEOMINT_BUILD_DIR: nothing recompiles) and no package index, then `import geomint` from another folder with no
# PYTHONPATH, and one run checked against a known number.
# cmake -DPYTHON=<interpreter> -DSOURCE=<source dir> -DBUILD=<build dir> -DWORK=<scratch dir> -P pip_install.cmake
foreach(var PYTHON SOURCE BUILD WORK)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "pip_install.cmake: -D${var}=... is required")
  endif()
endforeach()

# a fresh environment every time, and setup.py's staging (GEOMINT_BUILD_DIR/pip, where setuptools keeps the
# wheel's files between runs) gone: an earlier install must not pass for this one
file(REMOVE_RECURSE ${WORK} ${BUILD}/pip)
set(venv ${WORK}/venv)
include(${SOURCE}/cmake/run_step.cmake)

run("making the virtual environment" ${PYTHON} -m venv --system-site-packages ${venv})
# --no-index: pip must not look for anything on the network (numpy, setuptools and wheel are the system's)
run("pip install" ${CMAKE_COMMAND} -E env --unset=PYTHONPATH GEOMINT_BUILD_DIR=${BUILD}
    ${venv}/bin/pip install --no-index --no-build-isolation --no-cache-dir --disable-pip-version-check ${SOURCE})

# From a folder that holds no geomint, without PYTHONPATH: the module must come from the environment.
# The damped pendulum, la-midpoint at h = 0.1, against Boost.Odeint: the error tests/consumer/main.cpp checks.
file(MAKE_DIRECTORY ${WORK}/elsewhere)
file(WRITE ${WORK}/elsewhere/check.py [=[
import os
import sys

import numpy as np

import geomint

venv = os.path.realpath(sys.argv[1])
where = os.path.realpath(geomint.__file__)
assert where.startswith(venv + os.sep), f"geomint imported from {where}, not from the environment {venv}"
pendulum = geomint.system("pendulum")
run = pendulum.integrate("la-midpoint", h=0.1)
ref = pendulum.reference(h=0.1, kind="odeint", tol=1e-12)
err = float(np.max(np.abs(run["q"] - ref["q"])))
known = 5.3164828465e-03  # what the C++ consumer of the installed libraries gets (tests/consumer/main.cpp)
print(f"geomint from {where}: pendulum la-midpoint error {err:.10e} at h = 0.1")
assert abs(err / known - 1) < 1e-6, f"expected {known:.10e}"
]=])
execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=PYTHONPATH -- ${venv}/bin/python check.py ${venv}
                WORKING_DIRECTORY ${WORK}/elsewhere RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "importing the installed geomint failed (${rc}):\n${out}\n${err}")
endif()
message("${out}")
