"""The exact solutions and invariants of the nonholonomic benchmark suite (docs/nonholonomic-suite.md), derived
symbolically here from each system's Lagrangian, constraint rows and force as written in docs/systems/*.geomint:
the Lagrange-d'Alembert equations M q'' = dL/dq - (d^2L/dv dq) q' + F + A^T lambda with A q' = 0, then every
closed form the C++ suite uses (core/src/nonholonomic_suite.cpp) substituted into them. Nothing here calls geomint:
these are the derivations the C++ formulas are typed from, and a test of each."""
import pytest

sp = pytest.importorskip("sympy")
t = sp.symbols("t", real=True)


def lagrange_dalembert(L, q, v, A, F, at=None):
    """Accelerations and multipliers of L with rows A(q) v = 0 and force F, on the constraint (A q'' + A' q' = 0);
    with `at` (values of every symbol), their values there (the Euler-angle forms are too large to solve symbolically)."""
    n, m = len(q), A.shape[0]
    M = sp.hessian(L, v)
    rhs = sp.Matrix([sp.diff(L, q[i]) - sum(sp.diff(L, v[i], q[j]) * v[j] for j in range(n)) + F[i] for i in range(n)])
    Av = A * sp.Matrix(v)
    Adot_v = sp.Matrix([sum(sp.diff(Av[c], q[j]) * v[j] for j in range(n)) for c in range(m)])
    K = sp.zeros(n + m, n + m)
    K[:n, :n], K[:n, n:], K[n:, :n] = M, -A.T, A
    b = sp.Matrix.vstack(rhs, -Adot_v)
    if at is not None:
        K, b = K.subs(at).evalf(30), b.subs(at).evalf(30)
    sol = K.LUsolve(b)
    return sol[:n, :], sol[n:, :]


def on_path(expr, q, v, path):
    """expr(q, v) along q = path(t), v = path'(t)."""
    s = {qi: pi for qi, pi in zip(q, path)}
    s.update({vi: sp.diff(pi, t) for vi, pi in zip(v, path)})
    return expr.subs(s)


def vanishes(expr, points, tol=1e-12):
    """expr is zero at every point (dicts of symbol names to values), evaluated to 30 digits: the closed forms in
    tanh, sech and exponentials, whose symbolic simplification sympy does not find (or finds in minutes)."""
    syms = {str(s): s for s in expr.free_symbols}
    return all(abs(sp.N(expr.subs({syms[k]: v for k, v in pt.items() if k in syms}), 30)) < tol for pt in points)


# points for the closed forms: times and parameters away from any special value
POINTS = [dict(t=tt, m=1.3, I=0.7, a=0.4, alpha=al, V=1.1, c=cc, R=0.9, J=0.6, x0=0.2, y0=-0.1, theta0=0.3, phi0=0.1,
               omega0=1.2, spin0=-0.8) for tt in (0.0, 0.7, 4.0) for al in (0.05, 0.3) for cc in (-0.6, 0.4)]


def test_rolling_disk_damped_closed_form_and_multipliers():
    x, y, th, ph, vx, vy, vth, vph = sp.symbols("x y theta phi vx vy vth vph", real=True)
    m, I, J, R, al, x0, y0, th0, ph0, w0, s0 = sp.symbols("m I J R alpha x0 y0 theta0 phi0 omega0 spin0", positive=True)
    q, v = [x, y, th, ph], [vx, vy, vth, vph]
    L = m / 2 * (vx**2 + vy**2) + I / 2 * vth**2 + J / 2 * vph**2
    A = sp.Matrix([[1, 0, 0, -R * sp.cos(th)], [0, 1, 0, -R * sp.sin(th)]])
    acc, lam = lagrange_dalembert(L, q, v, A, [-al * m * vx, -al * m * vy, -al * I * vth, -al * J * vph])
    s = (1 - sp.exp(-al * t)) / al  # the undamped motion at the time s(t): damping proportional to the metric
    heading = th0 + w0 * s
    path = [x0 + R * s0 / w0 * (sp.sin(heading) - sp.sin(th0)), y0 - R * s0 / w0 * (sp.cos(heading) - sp.cos(th0)),
            heading, ph0 + s0 * s]
    for i in range(4):
        assert vanishes(on_path(acc[i], q, v, path) - sp.diff(path[i], t, 2), POINTS)
    for c in range(2):
        assert vanishes(on_path((A * sp.Matrix(v))[c], q, v, path), POINTS)
    # multipliers (force A^T lambda): m R omega0 spin0 e^{-2 alpha t} (-sin theta, cos theta)
    decay = sp.exp(-2 * al * t)
    assert vanishes(on_path(lam[0], q, v, path) + m * R * w0 * s0 * decay * sp.sin(heading), POINTS)
    assert vanishes(on_path(lam[1], q, v, path) - m * R * w0 * s0 * decay * sp.cos(heading), POINTS)


def test_chaplygin_sleigh_reduced_equations_and_damped_closed_form():
    x, y, th, vx, vy, vth = sp.symbols("x y theta vx vy vth", real=True)
    m, I, a, al, V, c = sp.symbols("m I a alpha V c", positive=True)
    u, w = sp.symbols("u omega", real=True)
    q, v = [x, y, th], [vx, vy, vth]
    L = m / 2 * (vx**2 + vy**2) + I / 2 * vth**2
    A = sp.Matrix([[-sp.sin(th), sp.cos(th), -a]])
    acc, lam = lagrange_dalembert(L, q, v, A, [-al * m * vx, -al * m * vy, -al * I * vth])
    J = I + m * a**2
    # u = x' cos th + y' sin th (speed along the heading), omega = th'; on the constraint the lateral speed is a omega
    on_c = {vx: u * sp.cos(th) - a * w * sp.sin(th), vy: u * sp.sin(th) + a * w * sp.cos(th), vth: w}
    udot = sp.cos(th) * acc[0] + sp.sin(th) * acc[1] + vth * (-sp.sin(th) * vx + sp.cos(th) * vy)
    assert sp.simplify(udot.subs(on_c) - (a * w**2 - al * u)) == 0
    assert sp.simplify(acc[2].subs(on_c) - (-m * a * u * w / J - al * w)) == 0
    assert sp.simplify(lam[0].subs(on_c) - m * I * u * w / J) == 0
    # undamped: u = V tanh(k t + c), omega = V sqrt(m/J) sech(k t + c), k = m a V / J, V^2 = u^2 + J omega^2 / m;
    # damped (Rayleigh alpha on every velocity): the same at s(t) = (1 - e^{-alpha t})/alpha, times e^{-alpha t}
    k = m * a * V / J
    s = (1 - sp.exp(-al * t)) / al
    uu = sp.exp(-al * t) * V * sp.tanh(k * s + c)
    ww = sp.exp(-al * t) * V * sp.sqrt(m / J) / sp.cosh(k * s + c)
    assert vanishes(sp.diff(uu, t) - (a * ww**2 - al * uu), POINTS)
    assert vanishes(sp.diff(ww, t) - (-m * a * uu * ww / J - al * ww), POINTS)
    assert vanishes(uu**2 + J * ww**2 / m - V**2 * sp.exp(-2 * al * t), POINTS)
    # the heading: th = th0 + sqrt(J/m)/a (gd(k s + c) - gd(c)), gd(x) = atan(sinh x)
    heading = sp.sqrt(J / m) / a * (sp.atan(sp.sinh(k * s + c)) - sp.atan(sp.sinh(c)))
    assert vanishes(sp.diff(heading, t) - ww, POINTS)


def euler_body_rates(ph, th, ps, vph, vth, vps):
    """Body angular velocity of the z-x-z Euler angles (precession phi, nutation theta, spin psi)."""
    return (vph * sp.sin(th) * sp.sin(ps) + vth * sp.cos(ps), vph * sp.sin(th) * sp.cos(ps) - vth * sp.sin(ps),
            vph * sp.cos(th) + vps)


def test_suslov_reduced_equations_in_euler_angles():
    ph, th, ps, vph, vth, vps = sp.symbols("phi theta psi vphi vtheta vpsi", real=True)
    I1, I2, I3, I13, I23 = sp.symbols("I1 I2 I3 I13 I23", real=True)
    q, v = [ph, th, ps], [vph, vth, vps]
    w = euler_body_rates(ph, th, ps, vph, vth, vps)
    Iten = sp.Matrix([[I1, 0, I13], [0, I2, I23], [I13, I23, I3]])
    W = sp.Matrix(w)
    L = (W.T * Iten * W)[0] / 2
    A = sp.Matrix([[sp.cos(th), 0, 1]])  # omega_3 = 0
    # omega_1', omega_2' along the flow, on the constraint (psi' = -phi' cos theta), against Suslov's
    #   I1 w1' = -(I13 w1 + I23 w2) w2,   I2 w2' = (I13 w1 + I23 w2) w1
    pts = [dict(phi=0.3, theta=1.1, psi=-0.4, vphi=0.7, vtheta=-0.5, I1=2, I2=3, I3=sp.Rational(9, 2), I13=0.4, I23=-0.3),
           dict(phi=-1.2, theta=0.6, psi=2.1, vphi=-0.3, vtheta=0.9, I1=1.5, I2=1, I3=2, I13=-0.2, I23=0.5)]
    for p in pts:
        at = {sp.Symbol(k, real=True): val for k, val in p.items()}
        at[vps] = -p["vphi"] * sp.cos(p["theta"])
        acc, _ = lagrange_dalembert(L, q, v, A, [0, 0, 0], at)
        w1, w2, w3 = (sp.N(wi.subs(at), 30) for wi in w)
        assert abs(w3) < 1e-25
        wdot = [sp.N(sum(sp.diff(wi, q[j]).subs(at) * v[j].subs(at) + sp.diff(wi, v[j]).subs(at) * acc[j]
                         for j in range(3)), 30) for wi in w[:2]]
        k = at[I13] * w1 + at[I23] * w2
        # to the round-off of the float inputs (0.4 is 0.4 + 2e-17)
        assert abs(at[I1] * wdot[0] + k * w2) < 1e-14
        assert abs(at[I2] * wdot[1] - k * w1) < 1e-14
        assert abs(at[I1] * wdot[0]) > 1e-3  # not zero by accident


def test_suslov_closed_form():
    I1, I2, E = sp.symbols("I1 I2 E", positive=True)
    I13, I23 = sp.symbols("I13 I23", real=True)
    c = sp.symbols("c", real=True)
    # on the energy ellipse I1 w1^2 + I2 w2^2 = 2E: w1 = A cos psi, w2 = B sin psi, and
    #   psi' = (B/(I1 A)) (I13 A cos psi + I23 B sin psi) = R cos(psi - psi*), tan psi* = I23 B / (I13 A),
    #   R = B sqrt(I13^2 A^2 + I23^2 B^2) / (I1 A), so sin(psi - psi*) = tanh(R t + c)
    A, B = sp.sqrt(2 * E / I1), sp.sqrt(2 * E / I2)
    r = sp.sqrt(I13**2 * A**2 + I23**2 * B**2)
    R = B * r / (I1 * A)
    star = sp.atan2(I23 * B, I13 * A)
    psi = star + sp.asin(sp.tanh(R * t + c))
    w1, w2 = A * sp.cos(psi), B * sp.sin(psi)
    pts = [dict(t=tt, c=cc, I1=2.0, I2=3.0, I13=0.4, I23=-0.3, E=0.7) for tt in (0.0, 0.8, 3.0) for cc in (-0.5, 0.9)]
    pts += [dict(t=tt, c=0.2, I1=1.5, I2=1.0, I13=-0.2, I23=0.5, E=2.0) for tt in (0.0, 1.5)]
    assert vanishes(I1 * sp.diff(w1, t) + (I13 * w1 + I23 * w2) * w2, pts)
    assert vanishes(I2 * sp.diff(w2, t) - (I13 * w1 + I23 * w2) * w1, pts)
    assert vanishes(I1 * w1**2 + I2 * w2**2 - 2 * E, pts)


def contact_oscillator(sigma):
    x, y, z, vx, vy, vz = sp.symbols("x y z vx vy vz", real=True)
    eps = sp.symbols("epsilon", real=True)
    q, v = [x, y, z], [vx, vy, vz]
    U = (x**2 + y**2 + z**2) / 2 + eps * x**2 * z**2 / 2
    # sigma: Modin-Verdier's non-reversible form, H = (|p + grad S|^2 + ...)/2 with S = sigma cos z, i.e. the
    # Lagrangian gains -grad S . v = sigma sin(z) z' (a total derivative: the same motion, other momenta)
    L = (vx**2 + vy**2 + vz**2) / 2 - U + sigma * sp.sin(z) * vz
    A = sp.Matrix([[1, 0, y]])  # x' + y z' = 0
    acc, lam = lagrange_dalembert(L, q, v, A, [0, 0, 0])
    H = (vx**2 + vy**2 + vz**2) / 2 + U
    Hy = (y**2 + vy**2) / 2
    return q, v, acc, lam, H, Hy, eps


@pytest.mark.parametrize("sigma", [0, sp.Rational(1, 5)])
def test_contact_oscillator_invariants(sigma):
    q, v, acc, _, H, Hy, _ = contact_oscillator(sigma)
    on_c = {v[0]: -q[1] * v[2]}
    for I in (H, Hy, H - Hy):
        rate = sum(sp.diff(I, q[i]) * v[i] + sp.diff(I, v[i]) * acc[i] for i in range(3))
        assert sp.simplify(rate.subs(on_c)) == 0
    # y decouples: y'' = -y (the reaction (1, 0, y) lambda has no y component), so y = y0 cos t + y0' sin t exactly
    assert sp.simplify(acc[1] + q[1]) == 0


def test_the_gauge_term_leaves_the_motion_as_it_was():
    _, _, acc0, lam0, _, _, _ = contact_oscillator(0)
    _, _, acc1, lam1, _, _, _ = contact_oscillator(sp.Rational(1, 5))
    assert sp.simplify(acc1 - acc0) == sp.zeros(3, 1)
    assert sp.simplify(lam1 - lam0) == sp.zeros(1, 1)
