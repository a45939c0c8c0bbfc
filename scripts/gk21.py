"""Gauss-Kronrod 10/21 nodes and weights on [-1, 1], computed from their definition.

The 21-point Kronrod rule adds to the 10 Gauss-Legendre nodes the 11 zeros of the Stieltjes
polynomial E_11, defined by  int_{-1}^{1} P_10(x) E_11(x) x^k dx = 0  for k = 0..10; its
weights make the rule exact for polynomials of degree <= 31. Everything is computed with
mpmath at 60 digits (linear solves on monomial moments) and rounded to the nearest double
for src/special/quad.rs. Run: python3 scripts/gk21.py  (needs mpmath).
"""
import mpmath as mp

mp.mp.dps = 60
N = 10


def moment(k):
    # int_{-1}^{1} x^k dx
    return mp.mpf(0) if k % 2 else mp.mpf(2) / (k + 1)


# P_10 in monomial coefficients.
p = mp.taylor(lambda x: mp.legendre(N, x), 0, N)
# E_11(x) = x^11 + sum_{j odd < 11} c_j x^j (odd by symmetry). For odd k the condition holds
# identically (odd integrand); the rows that are not identically zero are kept.
odd = [j for j in range(0, 11) if j % 2 == 1]
rows, rhs = [], []
for k in range(0, N + 1):
    row = []
    for j in odd:
        row.append(sum(p[i] * moment(i + j + k) for i in range(N + 1)))
    r = -sum(p[i] * moment(i + 11 + k) for i in range(N + 1))
    if any(abs(x) > 0 for x in row) or abs(r) > 0:
        rows.append(row)
        rhs.append(r)
A = mp.matrix(rows)
c = mp.lu_solve(A, mp.matrix(rhs))
coef = [mp.mpf(0)] * 12
coef[11] = mp.mpf(1)
for j, cj in zip(odd, c):
    coef[j] = cj
kron = sorted(mp.polyroots(coef[::-1], maxsteps=200, extraprec=200), key=lambda z: -mp.re(z))
kron = [mp.re(z) for z in kron]
gauss = sorted([mp.re(z) for z in mp.polyroots(p[::-1], maxsteps=200, extraprec=200)], key=lambda z: -z)
nodes = sorted(kron + gauss, key=lambda z: -z)
assert len(nodes) == 21
# Kronrod weights: exactness for x^0..x^20 (21 unknowns), then checked up to degree 31.
V = mp.matrix([[x ** k for x in nodes] for k in range(21)])
w = mp.lu_solve(V, mp.matrix([moment(k) for k in range(21)]))
for k in range(21, 32):
    assert abs(sum(w[i] * nodes[i] ** k for i in range(21)) - moment(k)) < mp.mpf(10) ** -40
# Gauss weights: 2 / ((1 - x^2) P_10'(x)^2).
wg = [2 / ((1 - x ** 2) * mp.diff(lambda t: mp.legendre(N, t), x) ** 2) for x in gauss]
print("// x (descending, x >= 0), Kronrod weight, is Gauss node, Gauss weight")
for i in range(11):
    x = nodes[i]
    isg = any(abs(x - g) < mp.mpf(10) ** -40 for g in gauss)
    gw = [wg[j] for j in range(10) if abs(gauss[j] - x) < mp.mpf(10) ** -40]
    print(repr(float(x)), repr(float(w[i])), isg, repr(float(gw[0])) if gw else "-")
