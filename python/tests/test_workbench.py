"""The module as a notebook's workbench: a Herglotz form inconsistent with the force is never a silent wrong system
(a GeomintWarning at the first contact-family run, an error at definition in strict mode, a warning on a program's
stderr); long calls stop on Ctrl-C within a second and leave the interpreter usable (a compilation of a shape at its first use
among them, in the module and in a program, and the compiler goes with it); a formula budget holds inside
an order; progress reaches a callback.

Run by ctest with the other module tests (python/CMakeLists.txt).
"""

import os
import signal
import subprocess
import sys
import textwrap
import time
import warnings

import pytest

import geomint

BIN = os.environ.get("GEOMINT_BIN_DIR", "build/experiments")
SRC = os.environ.get("GEOMINT_SOURCE_DIR", ".")

# The damped Duffing oscillator with the Herglotz form of twice its damping: the contact schemes would integrate
# q'' = -q - b q^3 - 2 alpha q' while the force says -alpha q'.
WRONG = dict(L="v1^2/2 - q1^2/2 - b*q1^4/4", herglotz="L - 2*alpha*z", force=["-alpha*v1"],
             parameters={"alpha": 0.2, "b": 0.5, "T": 5}, initial_q=["1"], initial_v=["0"])


def wrong_duffing(**kw):
    return geomint.define_system("duffing-wrong", coordinates=1, **WRONG, **kw)


def no_warnings(call):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = call()
    assert [str(w.message) for w in caught] == []
    return result


def test_an_inconsistent_herglotz_form_warns_at_the_first_contact_run_only():
    sys_ = wrong_duffing()
    no_warnings(lambda: sys_.integrate("la", h=0.1))  # LA runs the force: nothing to say
    with pytest.warns(geomint.GeomintWarning, match=r"^herglotz: the Herglotz Lagrangian is inconsistent with the force") as w:
        sys_.integrate("contact", h=0.1)
    assert issubclass(geomint.GeomintWarning, UserWarning)
    assert len(w) == 1
    # its equations give -q - b q^3 at the start (z = 0, v = 0): -1.5 both ways; the message names the sample point
    assert "the contact and LA schemes would integrate different systems" in str(w[0].message)
    no_warnings(lambda: sys_.integrate("contact", h=0.1))  # once per system
    no_warnings(lambda: sys_.convergence(["contact-trapezoid"], h_max=0.1, h_min=0.05))
    # a new system of the same formulas is a new system: it warns again, also from a composition of a contact scheme
    with pytest.warns(geomint.GeomintWarning, match="inconsistent with the force"):
        wrong_duffing().integrate("yoshida4:contact-trapezoid", h=0.1)


def test_a_consistent_herglotz_form_does_not_warn():
    ok = dict(WRONG, herglotz="L - alpha*z")
    no_warnings(lambda: geomint.define_system("duffing", coordinates=1, **ok).integrate("contact", h=0.1))


def test_strict_herglotz_refuses_the_system_at_its_definition():
    with pytest.raises(geomint.InputError, match=r"^herglotz: the Herglotz Lagrangian is inconsistent with the force"):
        wrong_duffing(strict_herglotz=True)
    # strict and consistent: defined, and runs
    ok = dict(WRONG, herglotz="L - alpha*z")
    run = geomint.define_system("duffing", coordinates=1, strict_herglotz=True, **ok).integrate("contact", h=0.1)
    assert run["steps"] == 50


def test_a_strict_system_file_is_refused_when_loaded(tmp_path):
    path = tmp_path / "wrong.geomint"
    path.write_text(WRONG_FILE)
    with pytest.raises(geomint.InputError, match=r"wrong.geomint:13: the Herglotz Lagrangian is inconsistent"):
        geomint.load_system(str(path), strict_herglotz=True)


WRONG_FILE = textwrap.dedent("""\
    [system]
    name = duffing-wrong
    description = a damped Duffing oscillator whose Herglotz form has twice the damping
    coordinates = 1

    [parameters]
    alpha = 0.2  # damping
    b = 0.5      # hardening
    T = 5        # horizon

    [dynamics]
    L = v1^2/2 - q1^2/2 - b*q1^4/4
    herglotz = L - 2*alpha*z
    F1 = -alpha*v1

    [initial]
    q1 = 1
    v1 = 0
    """)


def test_a_program_prints_the_warning_once_on_stderr(tmp_path):
    path = tmp_path / "wrong.geomint"
    path.write_text(WRONG_FILE)
    # two contact schemes and la, two h: four contact runs, one warning
    done = subprocess.run([os.path.join(BIN, "convergence"), "--system-file", str(path), "--schemes", "la", "contact",
                           "contact-trapezoid", "--h-max", "0.1", "--h-min", "0.05", "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    lines = [l for l in done.stderr.splitlines() if l.startswith("warning: ")]
    assert len(lines) == 1, done.stderr
    assert str(path) + ":13:" in lines[0] and "inconsistent with the force" in lines[0]
    # la alone: the force is what runs, nothing to warn
    done = subprocess.run([os.path.join(BIN, "integrate"), "--system-file", str(path), "--scheme", "la",
                           "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "warning" not in done.stderr, done.stderr


# ---------------------------------------------------------------------------------------------------------
# Interrupts and budgets

CHILD = textwrap.dedent("""\
    import sys, time, geomint
    what = sys.argv[1]
    pendulum = geomint.system("pendulum")
    sleigh = geomint.load_system(sys.argv[2])
    calls = {
        # about 1e8 generic Newton steps: far longer than the test waits
        "integrate": lambda: pendulum.integrate("la-midpoint", h=1e-5, params={"T": 1e3}, path="generic",
                                                every=10**5),
        # 1.5e6 steps of an eighth-order composition (17 Newton stages each) over four step sizes: about 3.5 s.
        # (A reference on ~1e7 output times spends up to a second filling its arrays between interruption points.)
        "convergence": lambda: pendulum.convergence(["kahanli8:la-midpoint"], h_max=1e-2, h_min=1.25e-3,
                                                    params={"T": 1000}),
        "ensemble": lambda: pendulum.ensemble("la", {"alpha": 0.01}, runs=10**4, h=1e-3, params={"T": 1e2},
                                              threads=2),
        # orders 0..5 in the velocities q': order 4 alone is half a minute of GiNaC, order 5 minutes
        "modified_formulas": lambda: sleigh.modified_formulas("la", order=5, budget=600),
        # a shape the build does not compile: compiled at its first use, half a minute of one core
        "compile": lambda: geomint.load_system(sys.argv[3]),
    }
    print("ready", flush=True)
    try:
        calls[what]()
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted %.6f" % time.monotonic(), flush=True)
    # the interpreter is usable: a short call works
    print("after", pendulum.integrate("la", h=0.1)["steps"], flush=True)
    """)


# five coupled oscillators: n = 5 without rows, a shape the build does not compile (core/src/formula/shapes.def), so
# that its first use compiles it (docs/systems/README.md, "Shapes the build did not compile")
FIVE = textwrap.dedent("""\
    [system]
    name = five-oscillators
    coordinates = 5
    [parameters]
    T = 1
    [dynamics]
    L = (v1^2 + v2^2 + v3^2 + v4^2 + v5^2)/2 - (q1^2 + (q2 - q1)^2 + (q3 - q2)^2 + (q4 - q3)^2 + (q5 - q4)^2)/2
    [initial]
    q1 = 0.1
    q2 = 0
    q3 = 0
    q4 = 0
    q5 = 0
    v1 = 0
    v2 = 0
    v3 = 0
    v4 = 0
    v5 = 0
    """)


def alive(pid):
    """The process exists and is not a zombie."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def compiler_under(pid):
    """The processes below pid once a compiler (cc1plus) is among them (5 s at most), from /proc."""
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        parent, names = {}, {}
        for name in os.listdir("/proc"):
            if name.isdigit():
                try:
                    with open("/proc/%s/stat" % name) as f:
                        comm, rest = f.read().split(" (", 1)[1].rsplit(")", 1)
                    parent[int(name)], names[int(name)] = int(rest.split()[1]), comm
                except (OSError, IndexError):
                    pass
        below, todo = set(), [pid]
        while todo:
            p = todo.pop()
            for c, pp in parent.items():
                if pp == p and c not in below:
                    below.add(c)
                    todo.append(c)
        if any(names[p] == "cc1plus" for p in below):
            return below
        time.sleep(0.05)
    raise AssertionError("no compiler under the process after 5 s")


def check_compiler_gone(processes, cache):
    """The compiler went with its caller (1.5 s at most), and the cache holds nothing half-made."""
    deadline = time.monotonic() + 1.5
    while any(alive(p) for p in processes) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(alive(p) for p in processes), "the compiler outlived its caller"
    left = sorted(f for f in os.listdir(cache) if f.endswith((".so", ".o", ".tmp")))
    assert left == [], left


@pytest.mark.parametrize("what", ["integrate", "convergence", "ensemble", "modified_formulas", "compile"])
def test_ctrl_c_stops_a_long_call_within_a_second_and_the_interpreter_goes_on(tmp_path, what):
    script = tmp_path / "child.py"
    script.write_text(CHILD)
    (tmp_path / "five.geomint").write_text(FIVE)
    cache = tmp_path / "cache"
    child = subprocess.Popen([sys.executable, str(script), what, os.path.join(SRC, "docs", "systems",
                                                                              "chaplygin-sleigh.geomint"),
                              str(tmp_path / "five.geomint")],
                             env=dict(os.environ, GEOMINT_SHAPE_CACHE=str(cache)),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "ready"
        time.sleep(1.0)  # well inside the call
        below = compiler_under(child.pid) if what == "compile" else set()
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=20)
    finally:
        child.kill()
    lines = out.splitlines()
    assert lines and lines[0].startswith("interrupted "), (out, err)
    delay = float(lines[0].split()[1]) - sent
    print("%s: KeyboardInterrupt %.3f s after SIGINT" % (what, delay))
    assert 0 <= delay < 1.0, delay
    assert lines[1] == "after 200", (out, err)
    assert child.returncode == 0, err
    if what == "compile":
        check_compiler_gone(below, cache)


def test_ctrl_c_stops_a_program_compiling_a_shape_and_the_compiler_with_it(tmp_path):
    (tmp_path / "five.geomint").write_text(FIVE)
    cache = tmp_path / "cache"
    child = subprocess.Popen([os.path.join(BIN, "integrate"), "--system-file", str(tmp_path / "five.geomint"),
                              "--scheme", "la", "--out", str(tmp_path / "out")],
                             env=dict(os.environ, GEOMINT_SHAPE_CACHE=str(cache)),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert "compiling the formula shape n = 5, m = 0" in child.stderr.readline()
        below = compiler_under(child.pid)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)  # to the program alone: the compiler is in a process group of its own
        out, err = child.communicate(timeout=20)
        delay = time.monotonic() - sent
    finally:
        child.kill()
    print("exit %d %.3f s after SIGINT: %s" % (child.returncode, delay, err.strip()))
    assert child.returncode == 128 + signal.SIGINT, err
    assert delay < 1.0, delay
    assert "interrupted by signal 2 (SIGINT); nothing was written" in err
    assert not (tmp_path / "out").exists()
    check_compiler_gone(below, cache)


def test_a_formula_budget_holds_inside_an_order():
    sleigh = geomint.load_system(os.path.join(SRC, "docs", "systems", "chaplygin-sleigh.geomint"))
    t0 = time.monotonic()
    # in the velocities q', orders 0..2 of the sleigh take about a second, order 3 several, order 4 half a minute
    with pytest.warns(geomint.GeomintWarning, match=r"budget of 3 s ran out in order (\d): the formulas hold orders") as w:
        f = sleigh.modified_formulas("la", order=4, budget=3)
    elapsed = time.monotonic() - t0
    assert elapsed < 4, elapsed
    assert f["stopped"] and f["K_asked"] == 4 and 0 <= f["K"] < 4
    assert "in order %d" % (f["K"] + 1) in str(w[0].message)
    # the orders finished are all there: F1..F3 and phi1 at every k <= K, none above
    ks = {r["k"] for r in f["rows"]}
    assert max(ks) <= f["K"] + 1 and f["K"] in ks  # phi is given one order further (its o = 1)
    assert {r["quantity"] for r in f["rows"] if r["k"] == f["K"]} >= {"F1", "F2", "F3"}
    assert f["seconds"] < 4


def test_progress_reaches_the_callback_in_the_programs_convention():
    seen = []
    geomint.system("pendulum").integrate("la-midpoint", h=1e-4, params={"T": 200}, path="generic", every=1000,
                                         progress=lambda fraction, message: seen.append((fraction, message)))
    assert seen, "no progress reported"
    fractions = [f for f, _ in seen]
    assert fractions == sorted(fractions) and 0 <= fractions[0] and fractions[-1] <= 1
    # the last report is the finished run's, however quickly it ran (no poll interval may have passed)
    assert seen[-1] == (1.0, "run: 2000000/2000000 steps (100%)")
    assert all(m.startswith("run: ") and "/2000000 steps (" in m for _, m in seen), seen[:3]


def test_a_progress_callback_that_raises_stops_the_call_with_its_error():
    class Stop(Exception):
        pass

    def stop(fraction, message):
        raise Stop(message)

    t0 = time.monotonic()
    with pytest.raises(Stop, match="run: "):
        geomint.system("pendulum").integrate("la-midpoint", h=1e-5, params={"T": 1e3}, path="generic", every=10**5,
                                             progress=stop)
    assert time.monotonic() - t0 < 1
    # a run too short for any poll: the callback's error at the run's last report is raised all the same
    with pytest.raises(Stop, match=r"\(100%\)"):
        geomint.system("pendulum").integrate("la", h=0.1, progress=stop)
    assert geomint.system("pendulum").integrate("la", h=0.1)["steps"] == 200
    with pytest.raises(geomint.InputError, match="progress must be a callable"):
        geomint.system("pendulum").integrate("la", h=0.1, progress=3)
