"""The module's reliability: every call plans its work with the programs' own budget before it starts (and each call
alone: a refused call leaves nothing behind), a numerical failure raises where a program would fail, and convergence
under mpiexec behaves as documented.

Run by ctest with the other module tests (python/CMakeLists.txt).
"""

import math
import os
import shutil
import subprocess
import sys
import time

import numpy as np
import pytest

import geomint

SRC = os.environ.get("GEOMINT_SOURCE_DIR", ".")


def refused_at_once(call, match):
    """call() raises InputError matching `match` within 2 s (the refusal comes from the plan, before any step)."""
    t0 = time.monotonic()
    with pytest.raises(geomint.InputError, match=match) as e:
        call()
    assert time.monotonic() - t0 < 2, "refused only after %.1f s" % (time.monotonic() - t0)
    return str(e.value)


PENDULUM = geomint.system("pendulum")


@pytest.mark.parametrize(
    "call",
    [
        # 1e11 steps of la on the pendulum, one row in 1e6 kept: the integrate program refuses the same run
        lambda: PENDULUM.integrate("la", h=0.1, params={"T": 1e10}, every=10**6),
        # 1e6 runs of 1e5 steps
        lambda: PENDULUM.ensemble("la", {"alpha": 0.01}, runs=10**6, params={"T": 1e4}),
        # 2e10 steps of the modified solution (each an Odeint step of the order-2 modified equation)
        lambda: PENDULUM.modified_agreement("la", 2, h=1e-9),
        # a composition of many stages, each a generic Newton step: 1e9 steps of it
        lambda: PENDULUM.integrate("kahanli8:la-midpoint", h=0.001, params={"T": 1e6}),
        # (200 + 2) x 2e8 steps of la: one measured run and 201 timed
        lambda: PENDULUM.work_precision(["la"], h=[1e-7], reps=200),
        # about 2e10 steps of each scheme over the 21 halvings from 0.1
        lambda: PENDULUM.convergence(["la", "la-trapezoid"], h_max=0.1, h_min=1e-7, params={"T": 1e3}),
    ],
    ids=["integrate", "ensemble", "modified_agreement", "composition", "work_precision", "convergence"],
)
def test_work_beyond_the_time_budget_is_refused_at_once_naming_the_python_opt_out(call):
    message = refused_at_once(call, "exceed the time budget")
    # the opt-out named is the keyword, not the programs' option Python does not have
    assert "budget=False to run it anyway" in message
    assert "--no-budget" not in message


def test_the_budget_is_per_call():
    # a refused call used to leave its planned total behind, and every later call failed with it
    for _ in range(2):
        refused_at_once(lambda: PENDULUM.work_precision(["la"], h=[1e-7], reps=200), "exceed the time budget")
    r = PENDULUM.integrate("la", h=0.1)
    assert r["steps"] == 200
    w = PENDULUM.work_precision(["la"], h=[0.1], reps=1)
    assert w["error"]["la"].shape == (1,)


def available_memory():
    with open("/proc/meminfo") as f:
        for line in f:
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) * 1024
    return math.inf


def test_kept_rows_beyond_the_memory_are_refused_even_without_the_budget():
    # 2e10 kept rows of 76 bytes, held twice (the run and its arrays): terabytes on any machine; budget=False
    # lifts the time budget (4e11 weighted steps), not the memory
    message = refused_at_once(lambda: PENDULUM.integrate("la", h=1e-9, budget=False), "memory available")
    assert "the run (2e+10 kept rows; raise every) needs 3.04e+06 MB" in message
    # the case: 2e8 rows of la at h = 1e-7 (about 30 GB with the arrays), on a machine with less available
    if available_memory() < 2e8 * 76 * 2:
        refused_at_once(lambda: PENDULUM.integrate("la", h=1e-7), r"the run \(200000001 kept rows; raise every\)")


def test_a_non_finite_state_raises_naming_the_step():
    # k = 1.2e29: the well's force overflows within the first steps; the program exits 3 on the same run
    knife = geomint.load_system(os.path.join(SRC, "docs", "systems", "knife-edge.geomint"))
    with pytest.raises(geomint.NumericalFailure, match=r"is not finite at t = ") as e:
        knife.integrate("la", h=0.1, params={"k": 1.2e29, "T": 1})
    assert e.value.quantity in ("state", "energy")
    assert 0 <= e.value.step <= 10
    assert "numerical failure at step %d" % e.value.step in str(e.value)


def test_a_non_finite_energy_is_named_where_it_happens():
    # at the initial data the system itself is refused (its energy 1/t is infinite at t = 0) ...
    with pytest.raises(geomint.InputError, match=r"the energy E is not finite at the initial data"):
        geomint.define_system(
            "inverse-t", coordinates=1, L="v1^2/2 - q1^2/2", energy="v1^2/2 + q1^2/2 + 1/t",
            parameters={"T": 1}, initial_q=["1"], initial_v=["0"]).integrate("la", h=0.125)
    # ... and along a run, the step where it stops being finite: 1/(t - 1/2) at t = 4 h, h = 1/8 (exact in binary)
    s = geomint.define_system(
        "inverse-t-half", coordinates=1, L="v1^2/2 - q1^2/2", energy="v1^2/2 + q1^2/2 + 1/(t - 1/2)",
        parameters={"T": 1}, initial_q=["1"], initial_v=["0"])
    with pytest.raises(geomint.NumericalFailure, match=r"the energy is not finite at t = 0.5") as e:
        s.integrate("la", h=0.125)
    assert e.value.step == 4
    assert e.value.quantity == "energy"


def test_a_non_finite_point_of_a_modified_equation_is_an_input_error():
    with pytest.raises(geomint.InputError, match=r"the point's q1 = nan is not finite"):
        PENDULUM.modified_equation("la", order=2, q=[float("nan")])
    with pytest.raises(geomint.InputError, match=r"the point's v1 = inf is not finite"):
        PENDULUM.modified_equation("la", order=2, q=[1.0], v=[float("inf")])
    # a finite point still gives the modified equation, with a residual near round-off
    r = PENDULUM.modified_equation("la", order=2, q=[1.0], v=[0.0])
    assert np.all(np.isfinite(r["F"]))


@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="no MPI launcher")
def test_convergence_under_mpiexec_gives_rank_0_the_results_as_documented(tmp_path):
    # the study's runs are shared by the ranks and gathered on rank 0 (System.convergence's docstring,
    # docs/cluster.md); a rank other than 0 gets the dict with no series. Each rank writes its own file: mpiexec
    # forwards the ranks' stdout in pieces, and two ranks' lines once came back interleaved within a line in CI.
    code = (
        "import geomint, os, sys; c = geomint.system('pendulum').convergence(['la'], h_max=0.1, h_min=0.025); "
        "r = os.environ.get('OMPI_COMM_WORLD_RANK'); "
        "open(os.path.join(sys.argv[1], 'rank' + r), 'w').write('%d %d' % (len(c['error'].get('la', [])), len(c['h'])))"
    )
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    done = subprocess.run(["mpiexec", "-q", "-n", "2", sys.executable, "-c", code, str(tmp_path)], env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    got = {f.name: f.read_text() for f in tmp_path.iterdir()}
    assert got == {"rank0": "3 3", "rank1": "0 3"}, (got, done.stdout)
