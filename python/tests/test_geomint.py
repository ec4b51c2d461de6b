"""The geomint module against the C++ programs (the same registry calls: the same text in their files, cell for
cell), against the scheme orders (fitted slopes), and on bad input (exceptions with the C++ message).

Run by ctest (python/CMakeLists.txt) with PYTHONPATH=build/python, GEOMINT_BIN_DIR (the programs) and
GEOMINT_SOURCE_DIR (docs/systems) set.
"""

import os
import subprocess

import numpy as np
import pytest

import geomint

BIN = os.environ.get("GEOMINT_BIN_DIR", "build/experiments")
SRC = os.environ.get("GEOMINT_SOURCE_DIR", ".")


def system_file(name):
    return os.path.join(SRC, "docs", "systems", name + ".geomint")


def program(name, *args, out):
    """Runs a geomint program (arguments as a list: nothing goes through a shell) writing into out."""
    cmd = [os.path.join(BIN, name), *[str(a) for a in args], "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done


def text(x):
    """A number as the programs write it (io.cpp format_number: 15 significant digits)."""
    if np.isnan(x):
        return "nan"
    return "%.15g" % x


def same_text(values, column):
    """Every value, printed as the programs print it, equals the file's cell (read back through read_tsv)."""
    values = np.ravel(values)
    assert len(values) == len(column)
    mismatches = [(i, text(a), text(b)) for i, (a, b) in enumerate(zip(values, column)) if text(a) != text(b)]
    assert not mismatches, mismatches[:5]


# ---------------------------------------------------------------------------------------------------------
# integrate: the program's table, cell for cell, for a header system and for a system file


@pytest.mark.parametrize(
    "how, args, scheme",
    [
        ("header", ["--system", "pendulum"], "contact"),
        ("file", ["--system-file", system_file("knife-edge")], "la"),
    ],
)
def test_integrate_is_the_program(tmp_path, how, args, scheme):
    params = {"alpha": 0.3, "T": 5}
    program("integrate", *args, "--scheme", scheme, "--h", 0.05, "--path", "generic", "--alpha", 0.3, "--T", 5,
            out=tmp_path)
    sys = geomint.system("pendulum") if how == "header" else geomint.load_system(system_file("knife-edge"))
    run = sys.integrate(scheme, h=0.05, params=params, path="generic")
    table = geomint.read_tsv(tmp_path / f"{sys.name}_{scheme}.tsv")
    # the header as a dict: the program, the system (and its file), the parameters as given
    assert table.meta["program"] == "integrate"
    assert table.meta["system"] == sys.name
    assert table.meta["alpha"] == "0.3"
    assert table.meta["steps"] == "100" == str(run["steps"])
    if how == "file":
        assert table.meta["system_file"] == system_file("knife-edge")
    n, m = sys.dof, sys.constraints
    assert run["q"].shape == (101, n) and run["lambda"].shape == (101, m)
    comp = (lambda base, i: base) if n == 1 else (lambda base, i: f"{base}{i + 1}")
    np.testing.assert_array_equal(run["j"], table["j"])
    same_text(run["t"], table["t"])
    for i in range(n):
        for base in ("q", "p", "v"):
            same_text(run[base][:, i], table[comp(base, i)])
    for c in range(m):
        same_text(run["lambda"][:, c], table["lambda" if m == 1 else f"lambda{c + 1}"])
    for col in ("z", "energy", "phi_d", "phi"):
        same_text(run[col], table[col])
    np.testing.assert_array_equal(run["newton"], table["newton"])


def test_formula_file_steps_to_the_header_bits():
    # the pendulum file associates as its header: the generic steps are the same bits (tests/formula/formula_systems.test.cpp)
    header = geomint.system("pendulum").integrate("la-midpoint", h=0.02, params={"alpha": 0.2, "T": 4}, path="generic")
    formula = geomint.load_system(system_file("pendulum")).integrate(
        "la-midpoint", h=0.02, params={"alpha": 0.2, "T": 4}, path="generic")
    for key in ("q", "p", "z", "energy"):
        np.testing.assert_array_equal(header[key], formula[key])
    assert np.max(np.abs(header["q"])) > 0.1  # a real motion


# ---------------------------------------------------------------------------------------------------------
# convergence: the program's numbers, and the orders of the schemes


def test_convergence_is_the_program(tmp_path):
    program("convergence", "--system-file", system_file("pendulum"), "--schemes", "la", "contact-trapezoid",
            "--h-max", 0.1, "--h-min", 0.01, "--T", 5, out=tmp_path)
    c = geomint.load_system(system_file("pendulum")).convergence(
        ["la", "contact-trapezoid"], h_max=0.1, h_min=0.01, params={"T": 5})
    rows = geomint.read_tsv(tmp_path / "pendulum_convergence.tsv")
    fits = geomint.read_tsv(tmp_path / "pendulum_convergence_fits.tsv")
    assert fits.meta["system_file"] == system_file("pendulum")
    for scheme in ("la", "contact-trapezoid"):
        keep = rows["scheme"] == scheme
        same_text(c["h"], rows["h"][keep])
        same_text(c["error"][scheme], rows["err_max"][keep])
        same_text([c["fitted_order"][scheme]], fits["fitted_order"][fits["scheme"] == scheme])


def duffing():
    # a system no header has: the damped Duffing oscillator, its Herglotz form consistent with the force
    return geomint.define_system(
        "duffing", coordinates=1,
        L="v1^2/2 - q1^2/2 - b*q1^4/4", herglotz="L - alpha*z", force=["-alpha*v1"],
        parameters={"alpha": (0.2, "Rayleigh damping"), "b": (0.5, "hardening"), "T": (5, "horizon")},
        initial_q=["1"], initial_v=["0"])


def test_a_system_defined_in_python_converges_at_every_schemes_order():
    sys = duffing()
    assert sys.warnings() == []
    # from h = 0.025 down: contact's observed order is 0.67 between h = 0.1 and 0.05 and reaches 0.99 only below
    # h = 0.01 (pre-asymptotic), which a fit from h = 0.1 would average in (0.91)
    c = sys.convergence(h_max=0.025, h_min=0.002)
    assert set(c["fitted_order"]) == {"la", "contact", "la-midpoint", "la-trapezoid", "contact-trapezoid"}
    for scheme, order in c["fitted_order"].items():
        assert abs(order - c["expected_order"][scheme]) < 0.1, (scheme, order)
    assert c["reference"].startswith("Boost.Odeint")


def test_a_formula_system_has_compositions_that_converge_at_their_order():
    # the Duffing oscillator of python: compositions of its symmetric schemes are schemes like the others
    sys = duffing()
    assert sys.compositions["yoshida4:la-trapezoid"]["order"] == 4
    assert sys.compositions["yoshida6a:contact-trapezoid"]["base"] == "contact-trapezoid"
    assert not any(":" in name for name in sys.schemes)  # run only when named
    c = sys.convergence(["yoshida4:la-trapezoid", "yoshida6a:la-midpoint"], h_max=0.2, h_min=0.025)
    for scheme, order in c["fitted_order"].items():
        assert abs(order - c["expected_order"][scheme]) < 0.15, (scheme, order, c["error"][scheme])


def test_work_precision_errors_are_the_convergence_errors():
    sys = geomint.system("oscillator")
    hs = [0.1, 0.05, 0.025]
    wp = sys.work_precision(["la"], h=hs, reps=1, reference="exact")
    c = sys.convergence(["la"], h_max=0.1, h_min=0.025, reference="exact")
    np.testing.assert_array_equal(wp["error"]["la"], c["error"]["la"])
    assert np.all(wp["seconds"]["la"] > 0)


def test_relative_error_is_long_horizons(tmp_path):
    # long_horizon's generic study and the module run one study: its err_rel (the error relative to the solution's
    # size over the last T) is the module's relative_error at that window, bit for bit, schemes and baselines alike
    program("long_horizon", "--system", "pendulum", "--horizons", 2, "--h-max", 0.1, "--h-min", 0.05, "--schemes", "la",
            "yoshida4:la-trapezoid", "--baselines", "odeint-rk4", "odeint-dopri5", "--tol", 1e-6, 1e-8, "--reps", 1,
            out=tmp_path)
    table = geomint.read_tsv(tmp_path / "pendulum_long_horizon.tsv")
    wp = geomint.system("pendulum").work_precision(
        ["la", "yoshida4:la-trapezoid"], h=[0.1, 0.05], params={"T": 40}, reps=1,
        baselines=["odeint-rk4", "odeint-dopri5"], tols=[1e-6, 1e-8], relative_window=20)
    for method in ("la", "yoshida4:la-trapezoid", "odeint-rk4", "odeint-dopri5"):
        rows = table["method"] == method
        assert [text(x) for x in wp["relative_error"][method]] == [text(x) for x in table["err_rel"][rows]], method
        assert [text(x) for x in wp["error"][method]] == [text(x) for x in table["err_max"][rows]], method
    # the relative error of a first-order scheme halves with h
    rel = wp["relative_error"]["la"]
    assert 1.8 < rel[0] / rel[1] < 2.2
    assert "relative_error" not in geomint.system("pendulum").work_precision(["la"], h=[0.1], reps=1)
    with pytest.raises(geomint.InputError, match="does not divide h-max"):  # refused before any run
        geomint.system("pendulum").work_precision(["la"], h=[0.1, 0.03], reps=1, relative_window=20)


def test_work_precision_measures_a_formula_the_user_writes():
    # the undamped oscillator's energy written by hand equals the energy the system derives, method by method; a
    # first-order scheme's energy error halves with h
    sys = geomint.system("oscillator")
    wp = sys.work_precision(["la", "la-midpoint"], h=[0.1, 0.05], params={"alpha": 0, "T": 10}, reps=1,
                            baselines=["odeint-dopri5"], tols=[1e-6], measures=["energy", "e=(v1^2 + q1^2)/2"])
    assert set(wp["measures"]) == {"energy", "e"}
    for method in ("la", "la-midpoint", "odeint-dopri5"):
        assert np.max(np.abs(wp["measures"]["energy"][method] - wp["measures"]["e"][method])) <= 1e-14, method
    la = wp["measures"]["energy"]["la"]
    assert 1.8 < la[0] / la[1] < 2.2
    with pytest.raises(geomint.InputError, match="unknown symbol 'x'"):
        sys.work_precision(["la"], h=[0.1], reps=1, measures=["r=x"])


def test_all_orders_flow_passes_through_every_step():
    # x' = G x, G = log(M)/h: exp(G t_j) x_0 (from G's eigenvectors) is the discrete (q_j, p_j) of la at every step
    sys = geomint.system("coupled-oscillators")
    ao = sys.all_orders("la", h=0.1, params={"T": 10})
    run = sys.integrate("la", h=0.1, params={"T": 10})
    x = np.hstack([run["q"], run["p"]])
    lam, V = np.linalg.eig(ao["G"])
    c = np.linalg.solve(V, x[0])
    flow = np.real(np.array([V @ (np.exp(lam * t) * c) for t in run["t"]]))
    assert np.max(np.abs(flow - x)) < 1e-12
    # p eliminated: q'' = A_v q' + A_q q; at this h close to the continuous -K q - alpha q' (here within 0.02)
    assert ao["A_q"].shape == (2, 2) and ao["A_v"].shape == (2, 2)
    assert abs(ao["A_v"][0, 0] + 0.1) < 0.02
    with pytest.raises(geomint.InputError):  # not a linear system
        geomint.system("pendulum").all_orders("la", h=0.1)


def test_work_precision_baselines_are_the_programs(tmp_path):
    # the module and the program run one study: the same errors, bit for bit, for schemes and baselines alike
    program("work_precision", "--system", "oscillator", "--T", 10, "--h-max", 0.1, "--h-min", 0.025, "--schemes", "la",
            "--baselines", "odeint-rk4", "odeint-dopri5", "gsl-rk8pd", "--tol", 1e-5, 1e-8, "--equations", "rhs",
            "--adaptive-error", "steps", "--reps", 1, out=tmp_path)
    table = geomint.read_tsv(tmp_path / "oscillator_work_precision.tsv")
    wp = geomint.system("oscillator").work_precision(
        ["la"], h=[0.1, 0.05, 0.025], params={"T": 10}, reps=1, baselines=["odeint-rk4", "odeint-dopri5", "gsl-rk8pd"],
        tols=[1e-5, 1e-8], equations="rhs", adaptive_error="steps")
    for method in ("la", "odeint-rk4", "odeint-dopri5", "gsl-rk8pd"):
        rows = table["method"] == method
        assert [text(x) for x in wp["error"][method]] == [text(x) for x in table["err_max"][rows]], method
        assert [text(x) for x in wp["value"][method]] == [text(x) for x in table["value"][rows]], method
    assert wp["knob"]["gsl-rk8pd"] == "tol"
    # a tighter tolerance is a smaller error, and rk8pd at 1e-8 is far below dopri5's at 1e-5
    assert wp["error"]["odeint-dopri5"][1] < wp["error"]["odeint-dopri5"][0]
    assert wp["error"]["gsl-rk8pd"][1] < 1e-3 * wp["error"]["odeint-dopri5"][0]


def test_convergence_measures_of_the_foucault_pendulum():
    # the measures the system declares come with its convergence study; the bob's distance (norm 2) is at least
    # the largest component of its error, and at most sqrt(2) times it
    sys = geomint.system("foucault")
    c2 = sys.convergence(["la", "contact"], h_max=0.1, h_min=0.025, params={"T": 4, "alpha": 1e-3}, norm="2")
    cm = sys.convergence(["la", "contact"], h_max=0.1, h_min=0.025, params={"T": 4, "alpha": 1e-3})
    assert set(c2["measures"]) == {"energy_err", "plane_err", "rate_rel_err", "min_r"}
    assert np.all(cm["error"]["la"] <= c2["error"]["la"])
    assert np.all(c2["error"]["la"] <= np.sqrt(2) * cm["error"]["la"] * (1 + 1e-12))
    # contact's chord energy is second order at small alpha, as its error is (its first-order terms are
    # proportional to alpha^2 and Omega sin beta); LA's is still pre-asymptotic over this range of h
    e = c2["measures"]["energy_err"]["contact"]
    assert 1.9 < np.log(e[0] / e[-1]) / np.log(4) < 2.1
    np.testing.assert_array_equal(c2["measures"]["min_r"]["la"], cm["measures"]["min_r"]["la"])


# ---------------------------------------------------------------------------------------------------------
# ensembles: the program's table, and the bits of each run alone


def test_ensemble_is_the_program(tmp_path):
    program("ensemble", "--system", "knife-edge", "--runs", 20, "--T", 5, "--path", "generic", "--perturb",
            "theta0=0.01", "u0=0.01", out=tmp_path)
    table = geomint.read_tsv(tmp_path / "ensemble_knife-edge_la_runs.tsv")
    e = geomint.system("knife-edge").ensemble("la", {"theta0": 0.01, "u0": 0.01}, runs=20, params={"T": 5},
                                              path="generic")
    assert e["perturbed"] == ["theta0", "u0"]
    same_text(e["values"][:, 0], table["theta0"])
    for i in range(3):
        same_text(e["q"][:, i], table["q%d" % (i + 1)])
    same_text(e["energy"], table["energy"])
    assert all(f == "" for f in e["failure"])


def test_an_ensemble_of_a_defined_system_runs_as_each_run_alone():
    sys = duffing()
    e = sys.ensemble("yoshida4:la-midpoint", {"alpha": 0.05, "b": 0.1}, runs=6, threads=2)
    one_thread = sys.ensemble("yoshida4:la-midpoint", {"alpha": 0.05, "b": 0.1}, runs=6, threads=1)
    np.testing.assert_array_equal(e["q"], one_thread["q"])
    for k in range(6):
        alpha, b = e["values"][k]
        assert abs(alpha - 0.2) <= 0.05 and abs(b - 0.5) <= 0.1
        alone = sys.integrate("yoshida4:la-midpoint", h=0.1, params={"alpha": alpha, "b": b})
        np.testing.assert_array_equal(alone["q"][-1], e["q"][k])
        np.testing.assert_array_equal(alone["v"][-1], e["v"][k])
    # and the runs differ: the perturbation reached them
    assert len(set(e["q"][:, 0])) == 6


def test_an_ensemble_records_failed_runs_and_refuses_bad_perturbations():
    # the contact scheme on the oscillator overflows (its action z first) within 500 steps once alpha > 30.3 at
    # h = 0.1 (tests/studies/generic_ensemble.test.cpp): alpha in [15, 45)
    e = geomint.system("oscillator").ensemble("contact", {"alpha": 15}, runs=40, params={"alpha": 30})
    alpha = e["values"][:, 0]
    failed = np.array([f != "" for f in e["failure"]])
    assert np.all(failed[alpha > 34]) and not np.any(failed[alpha < 27])
    assert np.all(np.isnan(e["q"][failed])) and np.all(np.isfinite(e["q"][~failed]))
    assert all("numerical failure at step" in f for f in np.array(e["failure"])[failed])
    with pytest.raises(geomint.InputError, match="has no parameter 'mass'"):
        geomint.system("knife-edge").ensemble("la", {"mass": 1})
    with pytest.raises(geomint.InputError, match="T is the horizon"):
        geomint.system("knife-edge").ensemble("la", {"T": 1})


# ---------------------------------------------------------------------------------------------------------
# modified equations: the program's coefficients, and the formulas


def test_modified_equation_is_the_program(tmp_path):
    program("modified_equation", "--system", "pendulum", "--schemes", "la", "contact", "--order", 4, "--q", 0.5, "--v", 0.3,
            out=tmp_path)
    table = geomint.read_tsv(tmp_path / "modified_equation.tsv")
    sys = geomint.system("pendulum")
    for scheme in ("la", "contact"):
        me = sys.modified_equation(scheme, order=4, q=[0.5], v=[0.3])
        keep = (table["scheme"] == scheme) & (table["component"] == "F0")
        same_text(me["F"][:, 0], table["value"][keep])


def test_modified_agreement_is_the_program_for_both_starts(tmp_path):
    program("modified_agreement", "--systems", "pendulum", "--schemes", "la", "--orders", 0, 1, "--T", 1, "--h-max", 0.1,
            "--halvings", 2, "--start", "shooting", "naive", "--threads", 1, out=tmp_path)
    table = geomint.read_tsv(tmp_path / "pendulum_modified_agreement.tsv")
    sys = geomint.system("pendulum")
    for start in ("shooting", "naive"):
        for K in (0, 1):
            keep = (table["start"] == start) & (table["K"] == K)
            errs = [sys.modified_agreement("la", K, h, T=1, params={"alpha": 0.5}, start=start)["err_q"]
                    for h in table["h"][keep]]
            same_text(errs, table["err_modified"][keep])
    with pytest.raises(geomint.InputError, match="unknown start 'euler'"):
        sys.modified_agreement("la", 1, 0.1, start="euler")


def test_modified_equation_of_the_formula_file_is_the_headers():
    header = geomint.system("pendulum").modified_equation("contact", order=4, q=[0.4], v=[-0.2], z=0.1, params={"alpha": 0.3})
    formula = geomint.load_system(system_file("pendulum")).modified_equation(
        "contact", order=4, q=[0.4], v=[-0.2], z=0.1, params={"alpha": 0.3})
    np.testing.assert_array_equal(header["F"], formula["F"])
    np.testing.assert_array_equal(header["Z"], formula["Z"])
    assert formula["residual"] < 1e-12


def test_modified_formulas_of_a_defined_system():
    sympy = pytest.importorskip("sympy")
    f = duffing().modified_formulas("la", order=2)
    assert f["K"] == 2 and not f["stopped"]
    rows = {(r["quantity"], r["k"]): r["text"] for r in f["rows"]}
    q, qdot, alpha, b, h = sympy.symbols("q1 v1 alpha b h")
    syms = {"q1": q, "v1": qdot, "alpha": alpha, "b": b, "h": h}
    # F_0 is the continuous equation: q'' = -q - b q^3 - alpha q'
    assert sympy.simplify(sympy.sympify(rows[("F", 0)], locals=syms) - (-q - b * q**3 - alpha * qdot)) == 0
    # F_1 is the numeric coefficient at the same point (the formula evaluated at the parameters' values)
    point = duffing().modified_equation("la", order=2, q=[0.7], v=[0.2])
    values = dict(f["values"])
    f1 = sympy.sympify(rows[("F", 1)], locals=syms).subs({q: 0.7, qdot: 0.2, alpha: values["alpha"], b: values["b"]})
    assert abs(float(f1) - point["F"][1, 0]) < 1e-14 * (1 + abs(point["F"][1, 0]))


def test_modified_equation_of_a_composition(tmp_path):
    # the program's coefficients; an order-4 composition's F_1..F_3 vanish to round-off and its F_4 does not, for a
    # header's system and for one defined by its formulas; its formulas are refused, saying why
    program("modified_equation", "--system", "pendulum", "--schemes", "yoshida4:la-trapezoid", "--order", 4,
            "--q", 0.5, "--v", 0.3, out=tmp_path)
    table = geomint.read_tsv(tmp_path / "modified_equation.tsv")
    me = geomint.system("pendulum").modified_equation("yoshida4:la-trapezoid", order=4, q=[0.5], v=[0.3])
    same_text(me["F"][:, 0], table["value"][table["component"] == "F0"])
    for F in (me["F"][:, 0], duffing().modified_equation("yoshida4:contact-trapezoid", order=4, q=[0.7], v=[0.2])["F"][:, 0]):
        assert np.max(np.abs(F[1:4])) < 1e-13 * abs(F[0])
        assert abs(F[4]) > 1e-3 * abs(F[0])
    with pytest.raises(geomint.InputError, match="is a composition: its modified equation is computed in numbers"):
        duffing().modified_formulas("yoshida4:la-trapezoid", order=2)


# ---------------------------------------------------------------------------------------------------------
# bad input: Python exceptions with the C++ message


def test_a_surrogate_is_a_system_whose_step_follows_the_run(tmp_path):
    # the paper's oscillator under la: order 1 on the base, 2 on its surrogate to K = 1 (integrate sets its step
    # parameter to its h); the program writes the same surrogate as a system file
    base = geomint.load_system(system_file("oscillator"))
    sur = base.surrogate("la", order=1)
    info = sur.surrogate_info
    assert info["K"] == 1 and info["step_parameter"] == "step"
    assert [c["symbolic_zero"] for c in info["checks"]] == [True, False]
    params = {"alpha": 0.5, "T": 10}
    hs = [0.1 / 2**k for k in range(4)]
    err_base, err_sur = [], []
    for h in hs:
        ref = base.reference(h, kind="odeint", params=params)
        err_base.append(np.max(np.abs(base.integrate("la", h, params=params, path="generic")["q"][:, 0] - ref["q"][:, 0])))
        err_sur.append(np.max(np.abs(sur.integrate("la", h, params=params)["q"][:, 0] - ref["q"][:, 0])))
    slope = lambda e: np.polyfit(np.log(hs), np.log(e), 1)[0]
    assert abs(slope(err_base) - 1) < 0.1 and abs(slope(err_sur) - 2) < 0.1
    program("surrogate", "--system-file", system_file("oscillator"), "--schemes", "la", "--order", 1, out=tmp_path)
    # the same formulas (GiNaC orders a sum's terms by its symbols' creation order, which differs from one process to
    # another: the same values to round-off, not bit for bit)
    filed = geomint.load_system(str(tmp_path / "oscillator-surrogate-la-1.geomint"))
    np.testing.assert_allclose(filed.integrate("la", 0.05, params={**params, "step": 0.05})["q"],
                               sur.integrate("la", 0.05, params=params)["q"], rtol=0, atol=1e-14)
    with pytest.raises(geomint.InputError, match="a surrogate is built from a system's formulas"):
        geomint.system("oscillator").surrogate("la", 1)
    with pytest.raises(geomint.InputError, match="not a surrogate"):
        base.surrogate_info


def test_errors_carry_the_cpp_message():
    sys = geomint.system("pendulum")
    with pytest.raises(geomint.InputError, match="unknown scheme 'leapfrog'.*known: la"):
        sys.integrate("leapfrog", h=0.1)
    with pytest.raises(ValueError, match="no parameter 'beta'"):
        sys.integrate("la", h=0.1, params={"beta": 1})
    with pytest.raises(geomint.InputError, match="h must be a positive"):
        sys.integrate("la", h=-1)
    with pytest.raises(geomint.InputError, match="L, column 13: formula ends"):
        geomint.define_system("bad", coordinates=1, L="v1^2/2 - q1*", parameters={"T": 1}, initial_q=["0"], initial_v=["1"])
    with pytest.raises(geomint.InputError, match="unknown"):
        geomint.define_system("bad", coordinates=1, L="v1^2/2 - k*q1^2", parameters={"T": 1}, initial_q=["0"], initial_v=["1"])


def test_a_numerical_failure_names_its_step():
    # q'' = q^3 leaves every bound in finite time (t = sqrt(2)/q0 = 0.47 from rest at q0 = 3): the step that
    # meets the non-finite state is named
    blowup = geomint.define_system("blowup", coordinates=1, L="v1^2/2 + q1^4/4", parameters={"T": 2},
                                   initial_q=["3"], initial_v=["0"])
    with pytest.raises(geomint.NumericalFailure) as failure:
        blowup.integrate("la", h=0.01)
    assert failure.value.step > 0
    assert f"step {failure.value.step}" in str(failure.value)
    assert "blowup" in str(failure.value)


# ---------------------------------------------------------------------------------------------------------
# read_tsv


def test_read_tsv_refuses_a_ragged_row(tmp_path):
    p = tmp_path / "ragged.tsv"
    p.write_text("# program: x\na\tb\n1\t2\n3\n")
    with pytest.raises(ValueError, match="ragged.tsv:4: 1 cells"):
        geomint.read_tsv(p)
