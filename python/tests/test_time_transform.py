"""The time transformation dt = g dsigma through the Python module (docs/time-transformation.md): the keyword of
load_system and define_system, the time t as the last coordinate of a run, and the refusals with their place.

Run by ctest with the module's other tests (python/CMakeLists.txt).
"""
import os

import numpy as np
import pytest

import geomint

SYSTEMS = os.path.join(os.environ.get("GEOMINT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")), "docs", "systems")


def test_the_time_is_the_last_coordinate_and_the_energy_the_physical_one():
    plain = geomint.load_system(os.path.join(SYSTEMS, "pendulum.geomint"))
    tt = geomint.load_system(os.path.join(SYSTEMS, "pendulum.geomint"), time_transform="1/(1 + q1*q1)")
    assert tt.dof == 2 and plain.dof == 1
    r = tt.integrate("la-midpoint", h=0.01, params={"alpha": 0, "p0": 0.5, "T": 5}, path="generic")
    t = r["q"][:, 1]
    assert t[0] == 0 and np.all(np.diff(t) > 0)
    # dt/dsigma = g = 1/(1 + q^2) <= 1: less physical time than sigma
    assert 0.2 * 5 < t[-1] < 5
    # Q'(0) = (v0 g0, g0) = (0.25, 0.5), and the energy column is the pendulum's, kept to O(h^2) without damping
    assert abs(r["v"][0, 0] - 0.25) < 1e-12 and abs(r["v"][0, 1] - 0.5) < 1e-12
    e = r["energy"]
    assert abs(e[0] - (0.125 + 1 - np.cos(1.0))) < 1e-14
    assert np.max(np.abs(e - e[0])) < 1e-3

def test_define_system_takes_a_monitor_and_refuses_a_bad_one_with_its_place():
    kw = dict(L="v1^2/2 - q1^2/2", parameters={"T": 5}, initial_q=[1], initial_v=[0])
    s = geomint.define_system("osc", 1, time_transform="2 + q1", **kw)
    assert s.dof == 2
    with pytest.raises(geomint.InputError) as e:
        geomint.define_system("osc", 1, time_transform="1 + w", **kw)
    assert "time_transform, column 5: unknown symbol 'w'" in str(e.value)
    with pytest.raises(geomint.InputError) as e:
        geomint.define_system("osc", 1, time_transform="q1 - 1", **kw).integrate("la", h=0.1)
    assert "the monitor g = dt/dsigma is 0 at the initial data" in str(e.value)


def test_a_time_transformed_run_starts_at_t0():
    # Lane-Emden from t0 = 1 with dt = t dsigma (t = e^sigma): g(t0) = 1, where g(0) = 0 would be refused
    le = geomint.load_system(os.path.join(SYSTEMS, "lane-emden.geomint"), time_transform="t")
    assert not le.has_exact  # the runs step in sigma; the file's solution is checked on the physical system
    r = le.integrate("la-midpoint", h=0.01, params={"T": 2}, path="generic")
    t, q = r["q"][:, 1], r["q"][:, 0]
    assert t[0] == 1 and abs(t[-1] - np.exp(2)) < 1e-2
    # against the exact solution sin(t)/t at the run's own times: second order in sigma, h = 0.01
    assert np.max(np.abs(q - np.sin(t) / t)) < 1e-4
