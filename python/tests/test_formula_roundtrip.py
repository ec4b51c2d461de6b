"""The round trip of formulas: modified_formulas writes the names define_system reads (q1.., v1.., the parameters'),
in a stable order, as text, Mathematica, LaTeX and (as_sympy) sympy objects; define_system reads its text and
sympy expressions; the consistent start of the modified solution is an API call (modified_start).

Run by ctest with PYTHONPATH=build/python (python/CMakeLists.txt).
"""

import numpy as np
import pytest

import geomint

sympy = pytest.importorskip("sympy")

# parameters named as sympy (beta) and Mathematica (I) name their own things: they come back unchanged
PARAMS = {"alpha": (0.2, "damping"), "beta": (0.3, "cubic damping"), "I": (1.5, "inertia"), "T": (2, "horizon")}
VALUES = {"alpha": 0.2, "beta": 0.3, "I": 1.5}
L_TEXT = "I*v1^2/2 - q1^2/2 - q1^4/8"
FORCE_TEXT = "-alpha*v1 - beta*v1^3"


def damped(name="damped", L=L_TEXT, force=FORCE_TEXT, parameters=None):
    return geomint.define_system(name, coordinates=1, L=L, force=[force], parameters=parameters or PARAMS,
                                 initial_q=["0.8"], initial_v=["0.1"])


def rows_of(f):
    return {(r["quantity"], r["k"]): r for r in f["rows"]}


def series(rows, quantity, K, step="step"):
    """sum_k step^k (row k), as formula text define_system reads."""
    return " + ".join(f"{step}^{k}*({rows[(quantity, k)]['text']})" for k in range(K + 1))


def test_formulas_come_back_in_the_names_that_went_in():
    f = damped().modified_formulas("la", order=2)
    assert f["symbols"] == ["h", "q1", "v1", "alpha", "beta", "I"]
    rows = rows_of(f)
    q1, v1, alpha, beta, I = sympy.symbols("q1 v1 alpha beta I")
    table = {"q1": q1, "v1": v1, "alpha": alpha, "beta": beta, "I": I}
    # F_0 is the system's own equation in the user's names: I q'' = -q - q^3/2 - alpha v - beta v^3
    from sympy.parsing.sympy_parser import convert_xor, standard_transformations

    F0 = sympy.parse_expr(rows[("F", 0)]["text"], local_dict=table,
                          transformations=standard_transformations + (convert_xor,))
    assert sympy.simplify(F0 - (-q1 - q1**3 / 2 - alpha * v1 - beta * v1**3) / I) == 0
    for r in f["rows"]:
        for old in ("betap", "Ip", "qdot"):
            assert old not in r["text"], r["text"]
    # Mathematica: a capitalized name is written in the Global` context (not Mathematica's imaginary unit I)
    assert "Global`I" in rows[("F", 0)]["mathematica"] and "beta" in rows[("F", 0)]["mathematica"]
    assert "\\dot{q}_{1}" in rows[("F", 0)]["latex"] and "\\beta" in rows[("F", 0)]["latex"]


def test_the_same_call_gives_the_same_text():
    a = damped().modified_formulas("la", order=2)
    # other formulas in between: GiNaC's own order of a sum's terms follows how many symbols the process has made
    geomint.system("pendulum").modified_formulas("contact", order=2)
    damped("other", parameters={"b": 1, "alpha": 0.1, "beta": 0.2, "I": 2, "T": 1}).modified_formulas("la", order=1)
    b = damped().modified_formulas("la", order=2)
    assert len(a["rows"]) == len(b["rows"]) == 9  # F, L, Fmod for k = 0, 1, 2
    for x, y in zip(a["rows"], b["rows"]):
        assert (x["text"], x["mathematica"], x["latex"]) == (y["text"], y["mathematica"], y["latex"])


def test_the_text_does_not_depend_on_the_order_the_parameters_were_declared():
    # GiNaC orders a sum's terms by hashes of its symbols' serial numbers, which follow the order the symbols are
    # made in: declared in reverse, the same system would print its terms in another order without the sort
    a = damped("forward").modified_formulas("la", order=2)
    b = damped("reversed", parameters=dict(reversed(list(PARAMS.items())))).modified_formulas("la", order=2)
    assert len(a["rows"]) == len(b["rows"]) == 9
    for x, y in zip(a["rows"], b["rows"]):
        assert (x["text"], x["mathematica"], x["latex"]) == (y["text"], y["mathematica"], y["latex"])


@pytest.mark.parametrize("name", ["h", "lambda", "if"])
def test_a_clashing_parameter_name_is_refused_naming_it(name):
    params = {**PARAMS, name: 0.5}
    with pytest.raises(geomint.InputError, match=f"parameter {name}"):
        damped(parameters=params)


def test_sympy_in_gives_the_same_system_as_the_string():
    q1, v1, alpha, beta, I = sympy.symbols("q1 v1 alpha beta I")
    L = I * v1**2 / 2 - q1**2 / 2 - q1**4 / 8
    F = -alpha * v1 - beta * v1**3
    from_text, from_sympy = damped(), damped("damped_sympy", L=L, force=F)
    # the same formulas of the modified equation, character for character (derived from the same expressions)
    a, b = from_text.modified_formulas("la", order=2), from_sympy.modified_formulas("la", order=2)
    assert [r["text"] for r in a["rows"]] == [r["text"] for r in b["rows"]]
    # and the same steps: the two tapes may add the terms in another order, so equal to round-off
    ra, rb = from_text.integrate("la", 0.05), from_sympy.integrate("la", 0.05)
    np.testing.assert_allclose(ra["q"], rb["q"], rtol=0, atol=1e-13)
    with pytest.raises(geomint.InputError, match="L: the function Abs"):
        damped("bad", L=sympy.Abs(v1) ** 3)


def test_as_sympy_is_the_numeric_modified_equation():
    # the user's symbols carry assumptions, so sympy.Symbol(name) would be another symbol: lambdify in the user's
    # symbols evaluates the formulas only if they are built from those
    q1, v1 = sympy.symbols("q1 v1", real=True)
    alpha, beta, I = sympy.symbols("alpha beta I", positive=True)
    system = damped("damped_sympy", L=I * v1**2 / 2 - q1**2 / 2 - q1**4 / 8, force=-alpha * v1 - beta * v1**3)
    K = 3
    f = system.modified_formulas("la", order=K, as_sympy=True)
    rows = rows_of(f)
    assert f["sympy_symbols"]["beta"] == beta and sympy.Symbol("beta") != beta
    assert rows[("F", 0)]["sympy"].free_symbols == {q1, v1, alpha, beta, I}
    Fk = [sympy.lambdify((q1, v1, alpha, beta, I), rows[("F", k)]["sympy"], "math") for k in range(K + 1)]
    rng = np.random.default_rng(7)
    for _ in range(10):
        q, v = rng.uniform(-1.5, 1.5, 2)
        params = {"alpha": rng.uniform(0, 1), "beta": rng.uniform(0, 1), "I": rng.uniform(0.5, 2)}
        point = system.modified_equation("la", order=K, q=[q], v=[v], params=params)
        for k in range(K + 1):
            x = Fk[k](q, v, params["alpha"], params["beta"], params["I"])
            # both evaluate the same exact coefficient in double: they differ by round-off of its terms only
            assert abs(x - point["F"][k, 0]) <= 1e-12 * (1 + abs(point["F"][k, 0])), (k, x, point["F"][k, 0])
    # subs and latex apply to them
    assert rows[("F", 0)]["sympy"].subs({alpha: 0, beta: 0, I: 1, q1: 0}) == 0
    assert "\\beta" in sympy.latex(rows[("F", 0)]["sympy"])


def test_the_modified_equation_read_back_is_the_modified_flow():
    # q'' = sum_k step^k F_k, written back as a system (L = v1^2/2 and that force), run from the consistent
    # start, is the modified solution modified_agreement compares the scheme with: both are Odeint (dopri5,
    # tol 1e-13) solutions of the same equation from the same start, so their distances to the scheme's steps
    # agree to the solvers' error (~1e-11 over these 40 steps), while the distance itself is O(h^3) (K = 2): a wrong coefficient, or a wrong start, shows as a difference of that size.
    system = damped()
    K, h, T = 2, 0.05, 2.0
    rows = rows_of(system.modified_formulas("la", order=K))
    start = system.modified_start("la", K, h)
    back = geomint.define_system(
        "modified", coordinates=1, L="v1^2/2", force=[series(rows, "F", K)],
        parameters={**PARAMS, "step": h}, initial_q=[repr(float(start["q"][0]))], initial_v=[repr(float(start["v"][0]))])
    flow = back.reference(h, kind="odeint", tol=1e-13)["q"][:, 0]
    steps = system.integrate("la", h)["q"][:, 0]
    assert len(flow) == len(steps) == round(T / h) + 1
    err = np.max(np.abs(steps - flow))
    agreement = system.modified_agreement("la", K, h, T=T, tol=1e-13)
    assert 1e-8 < agreement["err_q"] < 1e-2
    assert abs(err - agreement["err_q"]) < 1e-10


def test_the_modified_lagrangian_read_back_gives_the_modified_equation():
    # L~ = sum_k step^k L_k with the force sum_k step^k Fmod_k: its Euler-Lagrange equation is q'' = sum_k step^k
    # F_k up to O(step^(K+1)), so its flow from the same start leaves the modified flow's by O(h^(K+1)) over a
    # fixed time: the fitted slope over h = 0.1 .. 0.0125 is K + 1 = 3.
    system = damped()
    K = 2
    rows = rows_of(system.modified_formulas("la", order=K))
    hs = [0.1 / 2**k for k in range(4)]
    diffs = []
    for h in hs:
        start = system.modified_start("la", K, h)
        common = dict(coordinates=1, parameters={**PARAMS, "T": 1, "step": h},
                      initial_q=[repr(float(start["q"][0]))], initial_v=[repr(float(start["v"][0]))])
        by_F = geomint.define_system("by_F", L="v1^2/2", force=[series(rows, "F", K)], **common)
        by_L = geomint.define_system("by_L", L=series(rows, "L", K), force=[series(rows, "Fmod", K)], **common)
        a = by_F.reference(h, kind="odeint", tol=1e-13)["q"][:, 0]
        b = by_L.reference(h, kind="odeint", tol=1e-13)["q"][:, 0]
        diffs.append(np.max(np.abs(a - b)))
    slope = np.polyfit(np.log(hs), np.log(diffs), 1)[0]
    assert abs(slope - (K + 1)) < 0.15, (slope, diffs)


def test_modified_start_is_modified_agreements_shooting_start():
    system = damped()
    for K, h in ((1, 0.1), (2, 0.05)):
        start = system.modified_start("la", K, h)
        agreement = system.modified_agreement("la", K, h, T=1.0, tol=1e-13)
        # the same shooting, so the same velocity: v_shift is |v~(0) - v0|
        assert start["shift"] == pytest.approx(agreement["v_shift"], rel=1e-12, abs=1e-15)
        assert start["shift"] > 1e-3  # a first-order scheme: the start moves by O(h)
        np.testing.assert_allclose(start["q"], [0.8])
        np.testing.assert_allclose(start["v0"], [0.1])
    with pytest.raises(geomint.InputError, match="h must be a positive"):
        system.modified_start("la", 1, -0.1)
