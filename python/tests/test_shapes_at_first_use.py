"""Shapes compiled at their first use (docs/systems/README.md, "Shapes the build did not compile"): Ctrl-C during the
compilation stops it within a second, in the module (KeyboardInterrupt, and the interpreter goes on) and in a program
(exit 130), and the compiler goes with it; nothing half-made is left in the cache.

Run by ctest with the other module tests (python/CMakeLists.txt). Each test interrupts a compilation that would take
half a minute, so it costs a second or two of one core.
"""

import os
import signal
import subprocess
import sys
import textwrap
import time

BIN = os.environ.get("GEOMINT_BIN_DIR", "build/experiments")

# five coupled oscillators: n = 5 without rows, a shape the build does not compile (core/src/formula/shapes.def)
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

CHILD = textwrap.dedent("""\
    import sys, time, geomint
    try:
        geomint.load_system(sys.argv[1])
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted %.6f" % time.monotonic(), flush=True)
    print("after", geomint.system("pendulum").integrate("la", h=0.1)["steps"], flush=True)
    """)


def alive(pid):
    """The process exists and is not a zombie."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def descendants(pid):
    """The processes below pid (their pids), from /proc."""
    parent = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            try:
                with open("/proc/%s/stat" % name) as f:
                    parent[int(name)] = int(f.read().rsplit(")", 1)[1].split()[1])
            except OSError:
                pass
    found, todo = set(), [pid]
    while todo:
        p = todo.pop()
        for c, pp in parent.items():
            if pp == p and c not in found:
                found.add(c)
                todo.append(c)
    return found


def compiling(child):
    """Waits for the line that says the compilation starts, then for the compiler under the child; its processes."""
    line = child.stderr.readline()
    assert "compiling the formula shape n = 5, m = 0" in line, line
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        below = descendants(child.pid)
        names = set()
        for p in below:
            try:
                with open("/proc/%d/comm" % p) as f:
                    names.add(f.read().strip())
            except OSError:
                pass
        if "cc1plus" in names:
            return below
        time.sleep(0.05)
    raise AssertionError("no compiler under the process after 5 s")


def check_gone(processes, cache):
    deadline = time.monotonic() + 1.5
    while any(alive(p) for p in processes) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(alive(p) for p in processes), "the compiler outlived its caller"
    left = sorted(f for f in os.listdir(cache) if f.endswith((".so", ".o", ".tmp")))
    assert left == [], left


def test_ctrl_c_in_the_module_stops_a_compilation_within_a_second_and_the_interpreter_goes_on(tmp_path):
    (tmp_path / "five.geomint").write_text(FIVE)
    (tmp_path / "child.py").write_text(CHILD)
    cache = tmp_path / "cache"
    env = dict(os.environ, GEOMINT_SHAPE_CACHE=str(cache))
    child = subprocess.Popen([sys.executable, str(tmp_path / "child.py"), str(tmp_path / "five.geomint")], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        below = compiling(child)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)  # to the interpreter alone, as a notebook's interrupt is
        out, err = child.communicate(timeout=20)
    finally:
        child.kill()
    lines = out.splitlines()
    assert lines and lines[0].startswith("interrupted "), (out, err)
    delay = float(lines[0].split()[1]) - sent
    print("KeyboardInterrupt %.3f s after SIGINT" % delay)
    assert 0 <= delay < 1.0, delay
    assert lines[1] == "after 200", (out, err)
    assert child.returncode == 0, err
    check_gone(below, cache)


def test_ctrl_c_stops_a_program_compiling_a_shape_and_the_compiler_with_it(tmp_path):
    (tmp_path / "five.geomint").write_text(FIVE)
    cache = tmp_path / "cache"
    env = dict(os.environ, GEOMINT_SHAPE_CACHE=str(cache))
    child = subprocess.Popen([os.path.join(BIN, "integrate"), "--system-file", str(tmp_path / "five.geomint"),
                              "--scheme", "la", "--out", str(tmp_path / "out")], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        below = compiling(child)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)  # to the program alone: the compiler is in a group of its own
        out, err = child.communicate(timeout=20)
        delay = time.monotonic() - sent
    finally:
        child.kill()
    print("exit %d %.3f s after SIGINT: %s" % (child.returncode, delay, err.strip()))
    assert child.returncode == 128 + signal.SIGINT, err
    assert delay < 1.0, delay
    assert "interrupted by signal 2 (SIGINT); nothing was written" in err
    assert not (tmp_path / "out").exists()
    check_gone(below, cache)
