"""System files and formulas from other people, through the Python module: a refusal always has its message and
place, nothing it quotes reaches the user raw (a control byte, a carriage return, a NUL that would cut it), and a
system's per-model values are its own.

Run by ctest with the module's other tests (python/CMakeLists.txt).
"""

import math
import os

import numpy as np
import pytest

import geomint

BASE = """[system]
name = t
coordinates = 1
[parameters]
T = {T}  # the horizon{doc}
[dynamics]
L = v1^2/2 - q1^2/2{L}
[initial]
q1 = 1
v1 = 0
"""


def write(tmp_path, name, T="10", doc="", L=""):
    path = tmp_path / name
    path.write_bytes(BASE.format(T=T, doc=doc, L=L).encode("latin-1"))
    return str(path)


def test_latin1_degree_sign_is_refused_with_its_place(tmp_path):
    # A Latin-1 degree sign in a parameter's comment: it loaded, and .parameters raised UnicodeDecodeError.
    path = write(tmp_path, "latin1.geomint", doc=", 30\xb0")
    with pytest.raises(geomint.InputError) as e:
        geomint.load_system(path)
    assert str(e.value) == path + ":5:26: byte 0xb0 is not UTF-8 text: save the file as UTF-8"


def test_bytes_that_are_not_utf8_in_a_key_give_a_message(tmp_path):
    # A key quoted in the refusal was not UTF-8: the message could not be decoded and arrived empty.
    path = tmp_path / "key.geomint"
    path.write_bytes(BASE.format(T="10", doc="", L="").replace("L = ", "\xe9L = ").encode("latin-1"))
    with pytest.raises(geomint.InputError) as e:
        geomint.load_system(str(path))
    assert str(e.value) == str(path) + ":7:1: byte 0xe9 is not UTF-8 text: save the file as UTF-8"


def test_escape_sequence_in_a_file_is_refused_and_not_echoed(tmp_path):
    path = write(tmp_path, "esc.geomint", L=" # \x1b]0;retitled\x07")
    with pytest.raises(geomint.InputError) as e:
        geomint.load_system(path)
    message = str(e.value)
    assert message == path + ":7:23: control character (byte 0x1b): a system file is plain text"
    assert "\x1b" not in message and "\x07" not in message


def test_control_bytes_in_a_path_are_escaped_in_the_message():
    with pytest.raises(geomint.InputError) as e:
        geomint.load_system("/nonexistent/a\x1b[2Jb\rc.geomint")
    assert str(e.value) == "cannot read system file '/nonexistent/a\\x1b[2Jb\\rc.geomint': no such file"


@pytest.mark.parametrize("bad, column, byte", [("v1^2/2\r - q1", 7, "0x0d"), ("v1^2/2\x00 - q1", 7, "0x00")])
def test_control_bytes_in_a_formula_given_in_memory(bad, column, byte):
    # A carriage return stayed raw in the message; a NUL cut the message short.
    with pytest.raises(geomint.InputError) as e:
        geomint.define_system("m", 1, bad, parameters={"T": 10}, initial_q=[1], initial_v=[0])
    assert str(e.value) == "L, column %d: L has a control character or a byte that is not UTF-8 (byte %s)" % (column, byte)


def test_expectations_are_per_system(tmp_path):
    # Two systems of one shape: the second reported the first one's horizon cut (T = 20 for a T = 5 system).
    long_run = geomint.load_system(write(tmp_path, "long.geomint", T="500"))
    short_run = geomint.load_system(write(tmp_path, "short.geomint", T="5"))
    assert short_run.expectations["params"] == {}
    assert long_run.expectations["params"] == {"T": 20.0}
    again = geomint.load_system(write(tmp_path, "long2.geomint", T="500"))
    assert again.expectations["params"] == {"T": 20.0}


# ---------------------------------------------------------------------------------------------------------------
# The start (t0, z0) and an exact solution

SYSTEMS = os.path.join(os.environ.get("GEOMINT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")),
                       "docs", "systems")


def finest_slope(h, err, points=3):
    """The least-squares order over the `points` finest step sizes."""
    return np.polyfit(np.log(h[-points:]), np.log(err[-points:]), 1)[0]


def test_lane_emden_from_t0_converges_at_each_order_against_its_exact_solution():
    le = geomint.load_system(os.path.join(SYSTEMS, "lane-emden.geomint"))
    assert le.has_exact
    run = le.integrate("la-midpoint", h=0.5)
    assert run["t"][0] == 1.0 and run["t"][-1] == 11.0
    assert run["q"][0, 0] == math.sin(1.0)
    ref = le.reference(h=0.5, kind="exact")
    assert ref["q"][-1, 0] == math.sin(11.0) / 11.0
    c = le.convergence(schemes=["la", "contact", "la-midpoint", "contact-trapezoid"], h_max=0.1, h_min=0.003,
                       reference="exact")
    assert c["reference"] == "closed form"
    for scheme, order in {"la": 1, "contact": 1, "la-midpoint": 2, "contact-trapezoid": 2}.items():
        assert abs(finest_slope(c["h"], c["error"][scheme]) - order) < 0.1, (scheme, c["error"][scheme])


def lane_emden(exact_q, **kw):
    return geomint.define_system("le", coordinates=1, L="v1^2/2 - q1^2/2", force=["-2*v1/t"],
                                 parameters={"T": 10}, initial_q=["sin(1)"], initial_v=["cos(1) - sin(1)"], t0=1,
                                 exact_q=exact_q, **kw)


def test_define_system_takes_t0_and_an_exact_solution_and_refuses_a_wrong_one():
    le = lane_emden(["sin(t)/t"])
    assert le.convergence(schemes=["la-midpoint"], h_max=0.05, h_min=0.01, reference="exact")["reference"] == "closed form"
    # value and slope right at t0, q'' off by 2e-6 after: two hundred times the bound
    with pytest.raises(geomint.InputError, match=r"exact q1: the exact solution does not solve the equations.*residual"):
        lane_emden(["sin(t)/t + 1e-6*(t - 1)^2"])
    with pytest.raises(geomint.InputError, match="does not start at the initial data"):
        lane_emden(["cos(t)/t"])
    # no exact solution, no exact reference
    plain = geomint.define_system("p", coordinates=1, L="v1^2/2 - q1^2/2", parameters={"T": 1}, initial_q=["1"],
                                  initial_v=["0"])
    with pytest.raises(geomint.InputError, match="no closed-form solution"):
        plain.convergence(schemes=["la"], reference="exact")


def test_t0_shifts_the_forcing_and_z0_the_action():
    def forced(forcing, t0, z0=0):
        return geomint.define_system(f"f{t0}", coordinates=1, L="v1^2/2 - q1^2/2",
                                     herglotz=f"L - 0.2*z + q1*{forcing}", force=[f"-0.2*v1 + {forcing}"],
                                     parameters={"T": 6}, initial_q=["0.5"], initial_v=["-0.2"], t0=t0, z0=z0)
    late, shifted, early = forced("cos(3*t)", 2), forced("cos(3*(t + 2))", 0), forced("cos(3*t)", 0)
    for scheme in ["la", "contact-trapezoid"]:
        a, b, c = (s.integrate(scheme, h=0.01)["q"] for s in (late, shifted, early))
        assert np.max(np.abs(a - b)) < 1e-12   # the same motion on clocks 2 + j h and j h
        assert np.max(np.abs(a - c)) > 0.05    # what ignoring t0 would give
    # z0: the actions of two starts differ by z0 exp(-0.2 (t - t0)) (herglotz = L - 0.2 z + ...), to the scheme's order
    lifted = forced("cos(3*t)", 2, z0=1.5)
    errs, hs = [], [0.02, 0.01, 0.005]
    for h in hs:
        a, b = lifted.integrate("contact", h=h), late.integrate("contact", h=h)
        assert a["z"][0] == 1.5 and np.array_equal(a["q"], b["q"])
        errs.append(np.max(np.abs(a["z"] - b["z"] - 1.5 * np.exp(-0.2 * (a["t"] - 2)))))
    assert abs(finest_slope(np.array(hs), np.array(errs)) - 1) < 0.1, errs
