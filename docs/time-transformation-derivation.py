#!/usr/bin/env python3
# The derivation of docs/time-transformation.md checked by SymPy (about a minute): /usr/bin/python3 docs/time-transformation-derivation.py
# prints 0 for every residual.
# Verifies the extended (q, t) forms in sigma: on the reparametrized physical flow (t' = g, q' = v g) the extended
# Euler-Lagrange (forced) and Herglotz equations hold with w = 0, for a general L(t, q, v), F(t, q, v), g(t, q, v).
import sympy as sp
t, q, v, z, kap, alpha = sp.symbols('t q v z kappa alpha')
V = sp.Function('V'); f = sp.Function('f'); gf = sp.Function('g'); Ff = sp.Function('F'); mf = sp.Function('m')
# a general 1-dof L with a velocity-dependent mass and explicit t-dependence
L = mf(q) * v**2 / 2 - V(q) + q * f(t) + v * sp.sin(t) * q
F = Ff(t, q, v)
g = sp.exp(q * t / 5) / (1 + v**2 + q**2 * v)
# physical acceleration from d/dt L_v - L_q = F
a = sp.Symbol('a')
Lv = sp.diff(L, v)
dLv_dt = sp.diff(Lv, t) + sp.diff(Lv, q) * v + sp.diff(Lv, v) * a
acc = sp.solve(sp.Eq(dLv_dt - sp.diff(L, q), F), a)[0]
# extended: coordinates (Q1 = q, Q2 = t), velocities (P1 = q', P2 = t')
P1, P2, A1, A2 = sp.symbols('P1 P2 A1 A2')
sub = {v: P1 / P2}
Lbar = P2 * L.subs(sub) + kap / 2 * (P2 - g.subs(sub))**2
Fbar = [P2 * F.subs(sub), -F.subs(sub) * P1]
def total(expr):  # d/dsigma along (Q, Q', Q'')
    return sp.diff(expr, q) * P1 + sp.diff(expr, t) * P2 + sp.diff(expr, P1) * A1 + sp.diff(expr, P2) * A2
res = []
for Qi, Pi, Fi in [(q, P1, Fbar[0]), (t, P2, Fbar[1])]:
    res.append(total(sp.diff(Lbar, Pi)) - sp.diff(Lbar, Qi) - Fi)
# exact flow in sigma: P2 = g, P1 = v g, A1 = d/dsigma (v g) = g d/dt(v g) , A2 = g dg/dt
gd = sp.diff(g, t) + sp.diff(g, q) * v + sp.diff(g, v) * acc
on = {P1: v * g, P2: g, A1: g * (acc * g + v * gd), A2: g * gd}
print('forced LA, q and t rows on the exact flow:', [sp.simplify(r.subs(on)) for r in res])
# extended energy sum Q' dLbar/dQ' - Lbar equals w t' - w^2/(2 kappa)
w = kap * (P2 - g.subs(sub))
Ebar = P1 * sp.diff(Lbar, P1) + P2 * sp.diff(Lbar, P2) - Lbar
print('Ebar - (w t\' - w^2/(2 kappa)):', sp.simplify(Ebar - (w * P2 - w**2 / (2 * kap))))
print('Fbar . Qbar\':', sp.simplify(Fbar[0] * P1 + Fbar[1] * P2))
# Herglotz: Lh = L - alpha z (general), physical: d/dt Lh_v - Lh_q = Lh_z Lh_v ; z' = Lh
Lh = L + sp.Function('c')(q) * z * v - alpha * z  # z-dependence beyond Rayleigh
Lhv = sp.diff(Lh, v)
dLhv = sp.diff(Lhv, t) + sp.diff(Lhv, q) * v + sp.diff(Lhv, v) * a + sp.diff(Lhv, z) * Lh
acch = sp.solve(sp.Eq(dLhv - sp.diff(Lh, q), sp.diff(Lh, z) * Lhv), a)[0]
Hbar = P2 * Lh.subs(sub) + kap / 2 * (P2 - g.subs(sub))**2
def total_z(expr, zdot):
    return total(expr) + sp.diff(expr, z) * zdot
resh = []
zdot_sigma = Hbar  # z' = Hbar along sigma
for Qi, Pi in [(q, P1), (t, P2)]:
    resh.append(total_z(sp.diff(Hbar, Pi), zdot_sigma) - sp.diff(Hbar, Qi) - sp.diff(Hbar, z) * sp.diff(Hbar, Pi))
gdh = sp.diff(g, t) + sp.diff(g, q) * v + sp.diff(g, v) * acch
onh = {P1: v * g, P2: g, A1: g * (acch * g + v * gdh), A2: g * gdh}
print('Herglotz, q and t rows on the exact flow:', [sp.simplify(r.subs(onh)) for r in resh])
print('z\' = Hbar = g Lh on the flow:', sp.simplify(Hbar.subs(onh) - g * Lh))
# constraint: A(t,q) v + b(t,q) = 0 with multiplier; extended rows [A | b], multiplier lam_bar = t' lam
Af, bf, lam = sp.Function('A')(t, q), sp.Function('b')(t, q), sp.Symbol('lam')
# 1 dof cannot carry a constraint with motion; check the t row's balance: physical energy law with a constraint force
# lam*A: d/dt E = F v - L_t + lam A v = F v - L_t - lam b on A v + b = 0; the extended t row gets lam_bar * b.
E = v * Lv - L
dEdt = sp.diff(E, t) + sp.diff(E, q) * v + sp.diff(E, v) * a
# with constraint force lam*A in the q-row: acceleration
accc = sp.solve(sp.Eq(dLv_dt - sp.diff(L, q), F + lam * Af), a)[0]
lhs = dEdt.subs(a, accc)
print('energy law with a constraint force (should be F v - L_t + lam A v):', sp.simplify(lhs - (F * v - sp.diff(L, t) + lam * Af * v)))
res_c = []
Fbar_c = [P2 * F.subs(sub) + P2 * lam * Af, -F.subs(sub) * P1 + P2 * lam * bf]
for Qi, Pi, Fi in [(q, P1, Fbar_c[0]), (t, P2, Fbar_c[1])]:
    res_c.append(total(sp.diff(Lbar, Pi)) - sp.diff(Lbar, Qi) - Fi)
gdc = sp.diff(g, t) + sp.diff(g, q) * v + sp.diff(g, v) * accc
onc = {P1: v * g, P2: g, A1: g * (accc * g + v * gdc), A2: g * gdc}
r = [sp.simplify(x.subs(onc)) for x in res_c]
print('constrained rows on the exact flow (t row = lam g (A v + b), zero on the constraint):', r[0], sp.factor(r[1]))
