"""A million steps called from Python against the same registry call timed in C++ (make bench; here, not in
python/, whose geomint/ without the compiled module would shadow the build's).

The module's integrate() is the registry's run() plus the conversion of its result to numpy arrays; here only
the first and last steps are kept (every = N), so the difference is the cost of the call itself. Medians of
`REPS` runs after one warm-up, wall time (the machine is shared: run it twice and compare).
"""
import os
import statistics
import time

import geomint

N = 1_000_000
REPS = 5
SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def python_seconds(sys, scheme, h, params):
    sys.integrate(scheme, h=h, params=params, path="generic", every=N)  # warm-up
    times = []
    for _ in range(REPS):
        t0 = time.perf_counter()
        run = sys.integrate(scheme, h=h, params=params, path="generic", every=N)
        times.append(time.perf_counter() - t0)
        assert run["steps"] == N
    return statistics.median(times)


def main():
    h = 0.001
    params = {"T": N * h}
    cases = [
        ("pendulum (header)", geomint.system("pendulum"), "la"),
        ("pendulum (header)", geomint.system("pendulum"), "contact"),
        ("pendulum (formula file)", geomint.load_system(os.path.join(SRC, "docs", "systems", "pendulum.geomint")), "la"),
        ("knife-edge (header)", geomint.system("knife-edge"), "la"),
    ]
    print(f"A million steps (h = {h}, T = {N * h:g}, generic path), median of {REPS} after a warm-up, load "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'system':26} {'scheme':8} {'from Python ns/step':>20} {'from C++ ns/step':>17} {'Python/C++':>11}")
    for label, sys, scheme in cases:
        py = python_seconds(sys, scheme, h, params)
        cpp = geomint._geomint._seconds_of_run(sys, scheme, h, params, "generic", N, REPS)
        print(f"{label:26} {scheme:8} {py / N * 1e9:20.1f} {cpp / N * 1e9:17.1f} {py / cpp:11.3f}")


if __name__ == "__main__":
    main()
