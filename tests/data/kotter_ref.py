# ruff: noqa: E741  (l is the paper's name for the state)
"""Independent numpy reference for the Schottky-Koetter reduction (tests only).

Written from the paper's formulas (12)-(42) and the corrections pinned down in
``kotter_explore.py`` (see docs/errata.md); it does not import the
package. Conventions (the same ones the package documents in docs/kotter.md):

* state l = (l12, l13, l14, l23, l24, l34), m_j = l_kl, n_j = l_j4 (13),
  (j, k, l) cyclic: m = (l23, l31, l12), n = (l14, l24, l34);
* h0..h3 with the complementary-pair H2, H3 (erratum (7)/(15));
* F(s) (19) monic; at a root s_p the branch of sqrt(G) is
  sigma_p = -(h1 s_p^2 - h2 s_p + h3) / (2 h0) (so that f(s_p) = 0);
* sqrt(s_j4) principal, sqrt(s_kl) = sigma / sqrt(s_j4), sqrt(F'(s_p)) principal;
* root order: s1 = non-real root of largest Im, s2 its conjugate, s3 the
  remaining root of larger Im (then larger Re), s4 the last; all real: descending.
"""

from __future__ import annotations

import itertools

import numpy as np

CYC = ((0, 1, 2), (1, 2, 0), (2, 0, 1))
PAIRS = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


def full(l):
    l = np.asarray(l, dtype=float)
    m = np.zeros(l.shape[:-1] + (4, 4))
    for idx, (i, j) in enumerate(PAIRS):
        m[..., i, j] = l[..., idx]
        m[..., j, i] = -l[..., idx]
    return m


def cmat(a, b):
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    c = np.zeros((4, 4))
    for i in range(4):
        for j in range(4):
            if i != j:
                c[i, j] = (b[i] - b[j]) / (a[i] - a[j])
    return c


def frahm_rhs(a, b):
    """(1) literally: ldot_ij = sum_k (l_ik w_kj - w_ik l_kj), w_ij = c_ij l_ij."""
    c = cmat(a, b)

    def f(t, y):
        L = full(y)
        W = c * L
        D = L @ W - W @ L
        return np.array([D[i, j] for (i, j) in PAIRS])

    return f


def trajectory(a, b, l0, ts):
    from scipy.integrate import solve_ivp

    sol = solve_ivp(
        frahm_rhs(a, b),
        (0.0, float(ts[-1])),
        l0,
        method="DOP853",
        rtol=1e-13,
        atol=1e-13,
        t_eval=ts,
    )
    return sol.y.T


def mn(l):
    L = full(l)
    m = np.array([L[k, ll] for (j, k, ll) in CYC])
    n = np.array([L[j, 3] for (j, k, ll) in CYC])
    return m, n


def l_from_mn(m, n):
    # m = (l23, l31, l12), n = (l14, l24, l34)
    return np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])


def integrals(a, l, printed=False):
    """h0 (6) and h1, h2, h3 (7); printed=False: complementary pair (corrected)."""
    L = full(l)
    h0 = L[0, 1] * L[2, 3] + L[1, 2] * L[0, 3] + L[2, 0] * L[1, 3]
    h1 = h2 = h3 = 0.0
    for j, k in itertools.combinations(range(4), 2):
        p, q = [x for x in range(4) if x not in (j, k)]
        h1 += L[j, k] ** 2
        u, v = (j, k) if printed else (p, q)
        h2 += (a[u] + a[v]) * L[j, k] ** 2
        h3 += a[u] * a[v] * L[j, k] ** 2
    return np.array([h0, h1, h2, h3])


def s_pair(s, a, j, k):
    return (s - a[j]) * (s - a[k])


def l_of_s(s, a, l, sqrtG):
    """l(s) (12) on the branch sqrt(s_j4) sqrt(s_kl) = sqrtG."""
    m, n = mn(l)
    r = np.array([np.sqrt(complex(s_pair(s, a, j, 3))) for (j, k, ll) in CYC])
    return r * m + sqrtG / r * n


def m_of_s(s, a, l, sqrtG):
    """m(s) (17) on the same branch."""
    m, n = mn(l)
    r = np.array([np.sqrt(complex(s_pair(s, a, j, 3))) for (j, k, ll) in CYC])
    return sqrtG / r * m + r * n


def skew3(v):
    """L(s), M(s) of (18)."""
    return np.array([[0, v[2], -v[1]], [-v[2], 0, v[0]], [v[1], -v[0], 0]])


def F_coeffs(a, h):
    """(19): monic quartic, highest power first."""
    h0, h1, h2, h3 = h
    P = np.array([h1, -h2, h3])
    G = np.poly(a)
    return np.polysub(np.polymul(P, P), 4 * h0**2 * G) / (h1**2 - 4 * h0**2)


def F_roots(a, h):
    Fc = F_coeffs(a, h)
    r = np.roots(Fc).astype(complex)
    dF = np.polyder(Fc)
    for _ in range(4):
        r = r - np.polyval(Fc, r) / np.polyval(dF, r)
    return order_roots(r)


def order_roots(r):
    """The documented order; roots with |Im| at rounding level are made real and
    conjugate partners exact conjugates (F has real coefficients)."""
    scale = max(1.0, np.max(np.abs(r)))
    r = [complex(x.real, 0.0) if abs(x.imag) <= 1e-12 * scale else complex(x) for x in r]
    nonreal = [x for x in r if x.imag != 0.0]
    if nonreal:
        s1 = max(nonreal, key=lambda x: (x.imag, x.real))
        r.remove(s1)
        s2 = min(r, key=lambda x: abs(x - np.conj(s1)))
        r.remove(s2)
        s3, s4 = sorted(r, key=lambda x: (x.imag, x.real), reverse=True)
        if s3.imag != 0.0:
            s4 = np.conj(s3)
        return np.array([s1, np.conj(s1), s3, s4])
    return np.array(sorted(r, key=lambda x: x.real, reverse=True))


def sigma(sp, h):
    h0, h1, h2, h3 = h
    return -(h1 * sp * sp - h2 * sp + h3) / (2 * h0)


def uv(sp, a, h):
    """u_j = sqrt(s_j4)/sqrt(F'), v_j = sqrt(s_kl)/sqrt(F') at a root (branch sigma)."""
    Fc = F_coeffs(a, h)
    sf = np.sqrt(complex(np.polyval(np.polyder(Fc), sp)))
    r = np.array([np.sqrt(complex(s_pair(sp, a, j, 3))) for (j, k, ll) in CYC])
    return r / sf, sigma(sp, h) / r / sf


def l_p(sp, a, h, l):
    """(20) l^(p) = l(s_p)/sqrt(F'(s_p))."""
    m, n = mn(l)
    u, v = uv(sp, a, h)
    return u * m + v * n


def deltas(s, a, h):
    """Delta_j^(p) (25), corrected: (u^q v^r - u^r v^q), p,q,r cyclic in (1,2,3)."""
    W = [uv(x, a, h) for x in s[:3]]
    D = np.zeros((3, 3), complex)  # D[p, j]
    for p, q, r in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        D[p] = W[q][0] * W[r][1] - W[r][0] * W[q][1]
    return D


def kotter_constants(a, h, s):
    D = deltas(s, a, h)
    sqd = (D[0] - 1j * D[1]) / D[2]
    d = sqd**2
    u1, v1 = uv(s[0], a, h)
    u2, v2 = uv(s[1], a, h)
    D3 = D[2]
    alpha = (v2 + 1j * v1) / (2 * D3)
    beta = (v2 - 1j * v1) / (2 * D3)
    gamma = -(u2 + 1j * u1) / (2 * D3)
    delta = -(u2 - 1j * u1) / (2 * D3)
    return dict(D=D, sqrt_d=sqd, d=d, alpha=alpha, beta=beta, gamma=gamma, delta=delta)


def xi_eta(l, a, h, s):
    """(22)"""
    L1 = l_p(s[0], a, h, l)
    L2 = l_p(s[1], a, h, l)
    return L1 + 1j * L2, L1 - 1j * L2


def curve_c(d):
    """c~_j and c_j of (33) for d = (d1, d2, d3), d4 = d1 d2 d3."""
    d = np.asarray(d, complex)
    d4 = np.prod(d)
    ct = np.array([1 / ((d[j] - d[k]) * (d[j] - d[ll])) for (j, k, ll) in CYC])
    return ct, (d - d4) * ct, d4


def wurzel(d, z1, y1, z2, y2, branch):
    """P_j (27) and P_jk (28) literally, j, k = 0..4, with P_j = branch_j r_j(z1) r_j(z2),
    r_j = principal sqrt(z - d_j) for j < 4 and r_4 signed so that prod_j r_j(z) = y
    (the curve module's convention: prod_j P_j = y1 y2)."""
    dd = np.concatenate([[0.0], np.asarray(d, complex), [np.prod(d)]])

    def roots(z, y):
        r = np.sqrt(z - dd + 0j)
        if (np.conj(np.prod(r)) * y).real < 0:
            r[4] = -r[4]
        return r

    r1, r2 = roots(z1, y1), roots(z2, y2)
    P = np.asarray(branch) * r1 * r2
    Pjk = np.zeros((5, 5), complex)
    for j in range(5):
        for k in range(5):
            if j != k:
                Pjk[j, k] = (
                    P[j]
                    * P[k]
                    / (z1 - z2)
                    * (y1 / ((z1 - dd[j]) * (z1 - dd[k])) - y2 / ((z2 - dd[j]) * (z2 - dd[k])))
                )
    return P, Pjk


def h0_form(Kc):
    """H0 = sum_j m_j n_j by (23) as a quadratic form in xi, eta:
    sum_j p_j xi_j^2 + q_j xi_j eta_j + r_j eta_j^2, returns (p, q, r)."""
    al, be, ga, de = Kc["alpha"], Kc["beta"], Kc["gamma"], Kc["delta"]
    return al * ga, al * de + be * ga, be * de


def h0_form_sizes(Kc):
    """|p_j|, |alpha_j delta_j| + |beta_j gamma_j|, |r_j|: the sizes of the products that
    enter (p, q, r), against which their rounding is measured (q and p + r can cancel)."""
    al, be, ga, de = Kc["alpha"], Kc["beta"], Kc["gamma"], Kc["delta"]
    return np.abs(al * ga), np.abs(al * de) + np.abs(be * ga), np.abs(be * de)


def reduce_38_39(d, p, q, r, sizes=None):
    """Reduce sum p xi^2 + q xi eta + r eta^2 modulo the quadrics (11) to the form (38)
    A_j (xi_j^2 - eta_j^2) + B_j xi_j eta_j, and read off (39).

    Coefficient equations (lambda Q1 + mu Q2 + nu Q3 added):
      p_j + lam + nu d_j = A_j,  r_j + lam + nu/d_j = -A_j,  q_j + mu = B_j = delta (d_j + 1/d_j).
    Times d_j these are values at x = d_j of quadratics in x; with the Lagrange
    interpolant through d_1, d_2, d_3 (leading coefficient sum_j ct_j y_j, value at 0
    d4 sum_j ct_j y_j / d_j, linear coefficient -sum_j ct_j (d_k + d_l) y_j):
      existence:  sum_j c_j q_j = 0 and sum_j c_j (p_j + r_j) = 0   (c_j of (33)),
      delta = sum ct_j d_j q_j,  nu = -sum ct_j d_j (p_j + r_j),
      beta = (sum ct_j d_j (p_j - r_j) + nu)/2,  gamma = (d4 sum ct_j (p_j - r_j) - nu)/2,
      alpha = -sum ct_j (d_k + d_l) d_j (p_j - r_j) / 2.
    Returns a dict with the two existence sums (and the sizes of their terms, from
    ``sizes`` = (|p|, |q|, |r|) term by term if given), A, B and (alpha, beta, gamma, delta)."""
    sp, sq, sr = (np.abs(p), np.abs(q), np.abs(r)) if sizes is None else sizes
    d = np.asarray(d, complex)
    ct, c, d4 = curve_c(d)
    dkl = np.array([d[k] + d[ll] for (j, k, ll) in CYC])
    nu = -np.sum(ct * d * (p + r))
    delta = np.sum(ct * d * q)
    mu = np.sum(ct * dkl * d * q)  # minus the linear coefficient of delta x^2 - mu x + delta
    beta = 0.5 * (np.sum(ct * d * (p - r)) + nu)
    gamma = 0.5 * (d4 * np.sum(ct * (p - r)) - nu)
    alpha = -0.5 * np.sum(ct * dkl * d * (p - r))
    A = 0.5 * (p - r) + 0.5 * nu * (d - 1 / d)
    B = q + mu
    return dict(
        exist_B=np.sum(c * q),
        exist_B_size=np.sum(np.abs(c) * sq),
        exist_A=np.sum(c * (p + r)),
        exist_A_size=np.sum(np.abs(c) * (sp + sr)),
        A=A,
        B=B,
        abgd=np.array([alpha, beta, gamma, delta]),
    )


def abgd39_from_k_eps(k, eps, d):
    """(39) from K, eps of the corrected (40): reducing the representative
    p_j = K eps^2 d_j w_j, q_j = 2 K eps w_j, r_j = K w_j / d4 (w_j = 1/(d_j - d4)) with
    reduce_38_39 and the residue sums sum_j ct_j d_j^n w_j = d4^n / kappa (n <= 2),
    sum_j ct_j d_j^3 w_j = 1 + d4^3 / kappa (kappa = prod_m (d_m - d4)):
      beta = -K/kappa, gamma = eps^2 d4^2 K/kappa, delta = 2 eps d4 K/kappa,
      alpha = K/(2 kappa) (kappa eps^2 + (e1 - d4)(1 - eps^2 d4^2)), e1 = d1 + d2 + d3."""
    d = np.asarray(d, complex)
    d4 = np.prod(d)
    kap = np.prod(d - d4)
    e1 = np.sum(d)
    kk = k / kap
    return np.array(
        [
            0.5 * kk * (kap * eps**2 + (e1 - d4) * (1 - eps**2 * d4**2)),
            -kk,
            eps**2 * d4**2 * kk,
            2 * eps * d4 * kk,
        ]
    )
