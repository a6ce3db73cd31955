"""Derives the modified moments of inertia of the preprocessed DMV algorithm (dmv4 ... dmv10,
crates/core/src/systems/dmv.rs) and checks the tables `S` and `D` there against the derivation.

Construction (Hairer & Vilmart 2006, section 6): with the inverse moments u = (1/I1, 1/I2, 1/I3)
replaced by u~_j = s u_j + d, s = 1 + h^2 s3 + ..., d = h^2 d3 + ..., one DMV step (the Cayley
form: w = I~ e solves w = (alpha h/2) y - e x w, alpha = 1 + |e|^2, e = u~ o w; then
y1 = y - (4/(h alpha)) e x w and F = 1 + 2(e^ + e^2)/alpha) is expanded as a power series in h
with polynomial coefficients in y, and so is the exact flow of y' = y x (u o y), Q' = Q (u o y)^
from Q(0) = 1 (Lie series). The terms of order h^(2k+1) of the difference are s_{2k+1} times the
vector field for y (this fixes s_{2k+1}), and (s_{2k+1} u o y + d_{2k+1} y)^ for Q (this fixes
d_{2k+1}); each is written as a polynomial in H = 1/2 sum u_j y_j^2 and C = 1/2 |y|^2. Done at 30
random rational u, each coefficient of H^(k-i) C^i is then fitted exactly as a symmetric
polynomial in u in the elementary symmetric polynomials p1, p2, p3 (degree k + i for s, k + i + 1
for d).

Needs sympy (not a dependency of lieflow):  python scripts/dmv_coefficients.py  (about 15 s);
prints the tables as Rust and exits non-zero if dmv.rs differs.
"""

import pathlib
import random
import re
import sys
from fractions import Fraction

from sympy import QQ, Matrix, Rational
from sympy.polys.rings import ring

N = 9  # the highest power of h: s9, d9 (order 10)
R, y1, y2, y3 = ring("y1,y2,y3", QQ)
Y = [y1, y2, y3]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def hat(v):
    z = R(0)
    return [[z, -v[2], v[1]], [v[2], z, -v[0]], [-v[1], v[0], z]]


def smul(a, b):
    """Product of two truncated series (lists indexed by the power of h)."""
    out = [R(0)] * (N + 1)
    for i, x in enumerate(a):
        if x != 0:
            for j in range(N + 1 - i):
                if b[j] != 0:
                    out[i + j] += x * b[j]
    return out


def hc_basis_solve(p, basis):
    """Coefficients c with p = sum c_i basis_i (exact; asserts that they exist)."""
    mons = sorted(set(p.keys()).union(*(b.keys() for b in basis)))
    a = Matrix([[b.get(m, QQ(0)) for b in basis] for m in mons])
    rhs = Matrix([p.get(m, QQ(0)) for m in mons])
    sol = (a.T * a).solve(a.T * rhs)
    assert a * sol == rhs, "not a polynomial in H and C"
    return [Fraction(int(x.p), int(x.q)) for x in sol]


def derive(u):
    """s_{2k+1}, d_{2k+1} (k = 1..4) at one inverse inertia u: coefficients of H^(k-i) C^i."""
    u = [QQ(x) for x in u]
    H = sum((u[i] * Y[i] ** 2 for i in range(3)), R(0)) / 2
    C = sum((Y[i] ** 2 for i in range(3)), R(0)) / 2
    f = cross(Y, [u[i] * Y[i] for i in range(3)])

    def lie(g):
        return sum((g.diff(Y[i]) * f[i] for i in range(3)), R(0))

    fact = [1]
    for k in range(1, N + 1):
        fact.append(fact[-1] * k)
    ex_y, ex_q, cur = [], [], list(Y)
    w1 = hat([u[i] * Y[i] for i in range(3)])
    wk = [[R(int(i == j)) for j in range(3)] for i in range(3)]
    for k in range(N + 1):
        ex_y.append([c / fact[k] for c in cur])
        ex_q.append([[wk[i][j] / fact[k] for j in range(3)] for i in range(3)])
        cur = [lie(c) for c in cur]
        prod = [[sum((w1[i][m] * wk[m][j] for m in range(3)), R(0)) for j in range(3)]
                for i in range(3)]
        wk = [[prod[i][j] + lie(wk[i][j]) for j in range(3)] for i in range(3)]
    s_terms, d_terms = [], []

    def poly(co, k):
        return sum((QQ(c) * H ** (k - i) * C ** i for i, c in enumerate(co)), R(0))

    def dmv_step():
        s, d = [R(0)] * (N + 1), [R(0)] * (N + 1)
        s[0] = R(1)
        for m, co in enumerate(s_terms):
            s[2 * m + 2] = poly(co, m + 1)
        for m, co in enumerate(d_terms):
            d[2 * m + 2] = poly(co, m + 1)
        ut = [[s[k] * u[j] + d[k] for k in range(N + 1)] for j in range(3)]
        w = [[R(0)] * (N + 2) for _ in range(3)]
        e = [[R(0)] * (N + 2) for _ in range(3)]
        alpha = [R(1)] + [R(0)] * (N + 1)
        for k in range(1, N + 2):
            if k >= 2:
                alpha[k - 1] = sum((e[j][i] * e[j][k - 1 - i] for j in range(3)
                                    for i in range(1, k - 1)), R(0))
            cr = [R(0)] * 3
            for i in range(1, k):
                c = cross([e[j][i] for j in range(3)], [w[j][k - i] for j in range(3)])
                cr = [cr[j] + c[j] for j in range(3)]
            for j in range(3):
                w[j][k] = alpha[k - 1] * Y[j] / 2 - cr[j]
                e[j][k] = sum((ut[j][i] * w[j][k - i] for i in range(min(k, N + 1))), R(0))
        alpha = [R(1)] + [sum((e[j][i] * e[j][k - i] for j in range(3) for i in range(1, k)), R(0))
                          for k in range(1, N + 2)]
        inv = [R(1)] + [R(0)] * (N + 1)
        for k in range(1, N + 2):
            inv[k] = -sum((alpha[i] * inv[k - i] for i in range(1, k + 1)), R(0))
        exw = [[R(0)] * (N + 2) for _ in range(3)]
        for k in range(N + 2):
            for i in range(1, k):
                c = cross([e[j][i] for j in range(3)], [w[j][k - i] for j in range(3)])
                for j in range(3):
                    exw[j][k] += c[j]
        y_1 = [[-4 * sum((inv[i] * exw[j][k + 1 - i] for i in range(k + 2)), R(0))
                for k in range(N + 1)] for j in range(3)]
        for j in range(3):
            y_1[j][0] += Y[j]
        eh = [[[hat([e[j][k] for j in range(3)])[a][b] for k in range(N + 1)] for b in range(3)]
              for a in range(3)]
        F = [[None] * 3 for _ in range(3)]
        for a in range(3):
            for b in range(3):
                num = list(eh[a][b])
                for c in range(3):
                    num = [x + y for x, y in zip(num, smul(eh[a][c], eh[c][b]))]
                F[a][b] = [2 * x for x in smul(num, inv[:N + 1])]
                F[a][b][0] += R(int(a == b))
        return y_1, F

    for k in range(1, (N - 1) // 2 + 1):
        order = 2 * k + 1
        y_1, F = dmv_step()
        for m in range(1, order):
            assert all(y_1[j][m] == ex_y[m][j] for j in range(3)), (order, m)
            assert all(F[a][b][m] == ex_q[m][a][b] for a in range(3) for b in range(3)), (order, m)
        r = [y_1[j][order] - ex_y[order][j] for j in range(3)]
        c, rem = r[0].div(f[0])
        assert rem == 0 and all(r[j] == c * f[j] for j in range(3))
        basis = [H ** (k - i) * C ** i for i in range(k + 1)]
        s_co = hc_basis_solve(-c, basis)
        rq = [[F[a][b][order] - ex_q[order][a][b] for b in range(3)] for a in range(3)]
        v = [-rq[2][1], -rq[0][2], -rq[1][0]]
        sp = poly(s_co, k)
        dd, rem = (v[0] - sp * u[0] * Y[0]).div(Y[0])
        assert rem == 0 and all(v[j] - sp * u[j] * Y[j] == dd * Y[j] for j in range(3))
        s_terms.append(s_co)
        d_terms.append(hc_basis_solve(dd, basis))
    return s_terms, d_terms


def fit():
    """{(kind, k, i): [((a, b, c), coefficient of p1^a p2^b p3^c)]}, kind 0 = s, 1 = d."""
    random.seed(1)
    samples = []
    for _ in range(30):
        u = [Fraction(random.randint(1, 40), random.randint(1, 40)) for _ in range(3)]
        samples.append((u, derive(u)))
    out = {}
    for kind in (0, 1):
        for k in range(1, 5):
            for i in range(k + 1):
                m = k + i + kind
                basis = [(m - 3 * c - 2 * b, b, c) for c in range(m // 3 + 1)
                         for b in range((m - 3 * c) // 2 + 1)]
                rows, rhs = [], []
                for u, sd in samples:
                    p = (sum(u), u[0] * u[1] + u[1] * u[2] + u[2] * u[0], u[0] * u[1] * u[2])
                    rows.append([Rational(p[0] ** a * p[1] ** b * p[2] ** c) for a, b, c in basis])
                    rhs.append(Rational(sd[kind][k - 1][i]))
                a, r = Matrix(rows), Matrix(rhs)
                sol = (a.T * a).solve(a.T * r)
                assert a * sol == r, (kind, k, i)
                out[(kind, k, i)] = [(basis[j], sol[j]) for j in range(len(basis)) if sol[j] != 0]
    return out


def main():
    res = fit()
    derived = {}
    for kind, name in ((0, "S"), (1, "D")):
        derived[name] = [(k, i, a, b, c, int(v.p), int(v.q)) for k in range(1, 5)
                         for i in range(k + 1) for (a, b, c), v in res[(kind, k, i)]]
        print(f"const {name}: [Term; {len(derived[name])}] = [")
        for k, i, a, b, c, num, den in derived[name]:
            print(f"    t({k}, {i}, [{a}, {b}, {c}], {num}, {den}),")
        print("];")
    src = (pathlib.Path(__file__).resolve().parents[1] / "crates/core/src/systems/dmv.rs").read_text()
    ok = True
    for name in ("S", "D"):
        body = re.search(rf"const {name}: \[Term; \d+\] = \[(.*?)\];", src, re.S).group(1)
        table = [tuple(int(x) for x in re.findall(r"-?\d+", t))
                 for t in re.findall(r"t\(([^)]*)\)", body)]
        same = sorted(table) == sorted(derived[name])
        ok &= same
        print(f"dmv.rs table {name}: {'agrees with' if same else 'DIFFERS from'} the derivation")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
