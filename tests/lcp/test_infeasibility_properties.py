"""Property tests of issue 7: no method ever claims a solution that is not one.

Four generated families, each run through every method:

* ``psd``: ``M = [[S, -S], [-S, S]]`` (``S`` symmetric positive
  semidefinite), half of them plus a skew part ``K`` with ``K 1 = 0`` (then
  non-symmetric, the QP's "gap" formulation), permuted and scaled by powers
  of two (exact, so the stored data are infeasible, not nearly so), ``q <
  0``. Infeasible: ``y = 1`` is a Farkas vector (``M^T 1 = 0``, ``q.1 <
  0``). ``M`` is monotone, so Lemke's secondary ray is a proof and
  ``"lemke"`` and ``"auto"`` must report :data:`INFEASIBLE`, ``"auto"``
  without asking the QP.
* ``copositive``: ``M = [[P, C], [-C^T, N]]`` with ``P`` as above, ``N``
  nonnegative with a positive diagonal (indefinite as a rule) and ``1^T C
  <= 0``. Copositive-plus (``z.M z = z1.P z1 + z2.N z2``, and it vanishes
  only for ``z2 = 0``, ``P z1 = 0``) but of no class the code certifies;
  infeasible with the Farkas vector ``(1, 0)`` when ``1.q1 < 0``.
* ``zmatrix``: ``M = s I - B`` with ``B > 0`` and ``s < rho(B)``, ``q`` with
  ``q.y <= -margin`` for the Perron vector ``y > 0`` of ``B^T`` (``M^T y =
  (s - rho) y < 0``): strictly infeasible, not copositive.
* ``monotone``: ``M = A A^T + K`` (``K`` skew, ``A`` possibly rank
  deficient) with a planted solution: feasible and solvable; Lemke solves
  every one (Lemke's theorem for copositive-plus ``M``).

"Success implies the checks hold" is asserted with the test's own
:func:`assert_certified` (tolerances fixed by the data), on every method and
every family; on the infeasible families success itself is the failure.
"""

from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import moreau.lcp as lcp
from moreau.lcp import solve_lcp

from .conftest import assert_certified, assert_farkas

METHODS = ("lemke", "qp", "auto")
#: the tolerance each method's success is certified with by default
CERT_TOL = {"lemke": 1e-9, "qp": 1e-6, "auto": 1e-6}
#: generated cases per family, new ones each run (derandomize=False). The PSD family costs
#: 11 ms a case (6.8 s for 600), the others 2-4 ms: PSD and copositive-plus run 300 each
#: (1500 cases per run instead of 2000: 11.8 -> 6.8 s); the PSD breakdown Hypothesis found
#: once in about 2000 cases is kept as its own regression test below
EXAMPLES = {"psd": 300, "copositive": 300, "zmatrix": 500, "monotone": 400}


def _settings(family):
    return settings(max_examples=EXAMPLES[family], deadline=None, derandomize=False,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@st.composite
def _rng(draw):
    # Hypothesis draws the sizes, the knobs and a seed; numpy fills the
    # arrays from it. Drawing every entry through Hypothesis costs ten times
    # the solves; the zero masks below bring back what it would find first
    # (exact zeros, rank deficiency, ties).
    return np.random.default_rng(draw(st.integers(0, 2**63 - 1)))


@st.composite
def _zero_rate(draw):
    return draw(st.sampled_from([0.0, 0.0, 0.3, 0.7]))


def _entries(rng, shape, lo, hi, zeros):
    a = rng.uniform(lo, hi, shape)
    a[rng.random(shape) < zeros] = 0.0
    return a


def _skew_with_zero_sums(R, p1, p2):
    # K = [[0, G], [-G^T, 0]] with G = R - R P1 - P2 R + P2 R P1 (P1, P2
    # permutations, R integer): every row and column of G sums to exactly 0
    # in floating point, so K is skew and K 1 = 0 exactly. Infeasibility
    # must hold for the matrix as stored: a rounding-level K 1 would leave
    # feasible points near 1e16 that a solver may rightly find.
    G = R - R[:, p1] - R[p2, :] + R[p2][:, p1]
    k = len(R)
    K = np.zeros((2 * k, 2 * k))
    K[:k, k:] = G
    K[k:, :k] = -G.T
    return K


def _scramble(M, q, rng):
    # P D M D P^T and P D q with D = diag(2^e), e in -3..3: a permutation and
    # a positive diagonal congruence keep the class (PSD, copositive-plus)
    # and map Farkas vectors y to P D^-1 y; powers of two keep the data
    # exact, so the stored instance is infeasible, not just nearly so
    n = len(q)
    d = np.ldexp(1.0, rng.integers(-3, 4, n))
    perm = rng.permutation(n)
    M = d[:, None] * M * d[None, :]
    q = d * q
    return M[np.ix_(perm, perm)].copy(), q[perm].copy()


@st.composite
def psd_infeasible(draw):
    rng = draw(_rng())
    zeros = draw(_zero_rate())
    k = draw(st.integers(1, 5))
    r = draw(st.integers(1, k))
    A = _entries(rng, (k, r), -3, 3, zeros)
    S = A @ A.T + draw(st.sampled_from([0.0, 1e-3, 0.5])) * np.eye(k)
    M = np.block([[S, -S], [-S, S]])
    m = 2 * k
    if draw(st.booleans()):
        R = rng.integers(-3, 4, (k, k)).astype(float)
        M = M + _skew_with_zero_sums(R, rng.permutation(k), rng.permutation(k))
    q = -rng.uniform(0.01, 10.0, m)
    M, q = _scramble(M, q, rng)
    return np.ldexp(M, draw(st.integers(-10, 10))), q


@st.composite
def copositive_plus_infeasible(draw):
    rng = draw(_rng())
    zeros = draw(_zero_rate())
    k = draw(st.integers(1, 3))
    p = draw(st.integers(1, 4))
    m = 2 * k
    A = _entries(rng, (k, k), -2, 2, zeros)
    S = A @ A.T + draw(st.sampled_from([0.0, 1e-3, 0.5])) * np.eye(k)
    P = np.block([[S, -S], [-S, S]])
    C = _entries(rng, (m, p), -2, 2, zeros)
    # columns of C summing to < 0 keep y = (1, 0) a Farkas vector; the
    # margin keeps the sign through rounding
    C = C - (np.maximum(C.sum(axis=0), 0.0) + rng.uniform(0.01, 1.0, p))[None, :] / m
    N = _entries(rng, (p, p), 0.0, 5.0, zeros)
    N[np.diag_indices(p)] = rng.uniform(0.05, 1.0, p)
    M = np.block([[P, C], [-C.T, N]])
    q1 = _entries(rng, m, -5, 5, zeros)
    q1 = q1 - (q1.sum() + rng.uniform(0.01, 5.0)) / m
    q = np.concatenate([q1, _entries(rng, p, -5, 5, zeros)])
    return _scramble(M, q, rng)


@st.composite
def zmatrix_infeasible(draw):
    rng = draw(_rng())
    n = draw(st.integers(1, 8))
    B = rng.uniform(0.05, 2.0, (n, n))
    B[np.diag_indices(n)] = 0.0
    if n == 1:
        B[0, 0] = 1.0  # a positive 1 x 1 "B"; M = s - 1 < 0
    lam, V = np.linalg.eig(B.T)
    j = int(np.argmax(lam.real))
    rho = float(lam[j].real)
    y = np.abs(V[:, j].real)
    y /= y.max()
    s = rho * draw(st.floats(-0.5, 0.95))
    M = s * np.eye(n) - B if n > 1 else np.array([[s - 1.0]])
    q = _entries(rng, n, -5, 5, draw(_zero_rate()))
    # strictly infeasible: q.y at least `margin` max|q| below zero
    margin = draw(st.floats(0.01, 1.0))
    q = q - (q @ y + margin * max(1.0, np.max(np.abs(q)))) * y / (y @ y)
    return M, q


@st.composite
def monotone_feasible(draw):
    rng = draw(_rng())
    zeros = draw(_zero_rate())
    n = draw(st.integers(1, 10))
    r = draw(st.integers(1, n))
    A = _entries(rng, (n, r), -2, 2, zeros)
    B = _entries(rng, (n, n), -2, 2, zeros)
    M = A @ A.T + B - B.T
    active = rng.random(n) < draw(st.sampled_from([0.0, 0.5, 1.0]))
    zs = np.where(active, rng.uniform(0.1, 3.0, n), 0.0)
    ws = np.where(active, 0.0, rng.uniform(0.1, 3.0, n))
    return M, ws - M @ zs


def run_every_method(M, q, feasible):
    """Solve with every method; return the results and the broken promises (empty when all hold)."""
    results = {}
    broken = []
    for method in METHODS:
        res = results[method] = solve_lcp(M, q, method=method)
        if not (np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w))):
            broken.append(f"{method}: non-finite z or w")
        if not res.success:
            continue
        if not feasible:
            broken.append(f"{method}: success on an infeasible LCP (z = {res.z}, w = {M @ res.z + q})")
            continue
        try:
            assert_certified(M, q, res.z, CERT_TOL[method])
        except AssertionError as exc:
            broken.append(f"{method}: success, but {exc}")
    return results, broken


def infeasibility_claims_carry_a_proof(M, q, results):
    for method, res in results.items():
        if res.status == lcp.INFEASIBLE:
            assert_farkas(M, q, res.certificate, rtol=1e-6)
        else:
            assert res.certificate is None, method


@_settings("psd")
@given(psd_infeasible())
def test_psd_family(prob):
    M, q = prob
    results, broken = run_every_method(M, q, feasible=False)
    assert broken == []
    infeasibility_claims_carry_a_proof(M, q, results)
    # Lemke's secondary ray with a certified PSD M is a proof, and auto
    # takes it without asking the QP. About 1 case in 2000 Lemke breaks down
    # before the ray instead (an honest failure status, see
    # test_psd_breakdown_is_caught_by_the_certified_qp); auto then proves
    # infeasibility through the QP's checked certificate.
    # Since issue 16 a ray is a proof only through a Farkas vector that holds
    # exactly on the stored data; where rounding keeps the ray from giving
    # one, SECONDARY_RAY is the honest answer (the stored M is singular only
    # up to rounding in some members: S = A A^T is computed in floats).
    lem, auto = results["lemke"], results["auto"]
    assert lem.status in (lcp.INFEASIBLE, lcp.SECONDARY_RAY, lcp.BREAKDOWN), lem.message
    assert not auto.success
    if lem.status == lcp.INFEASIBLE:
        assert auto.status == lcp.INFEASIBLE
        for res in (lem, auto):
            assert res.path == ("lemke",) and "copositive-plus" in res.message


def test_psd_breakdown_is_caught_by_the_certified_qp():
    # an 8 x 8 member of the PSD family (found by Hypothesis) on which Lemke's
    # lexicographic pivoting broke down after 9 pivots: no false success, and
    # an infeasibility claim only with a certificate that checks out
    data = np.load(Path(__file__).parents[1] / "data" / "psd_lemke_breakdown.npz")
    M, q = data["M"], data["q"]
    lem = lcp.solve_lcp(M, q, method="lemke")
    assert not lem.success and lem.status in (lcp.INFEASIBLE, lcp.SECONDARY_RAY, lcp.BREAKDOWN)
    auto = lcp.solve_lcp(M, q, method="auto")
    assert not auto.success
    if auto.status == lcp.INFEASIBLE:
        assert_farkas(M, q, auto.certificate, rtol=1e-6)


@_settings("copositive")
@given(copositive_plus_infeasible())
def test_copositive_plus_family(prob):
    M, q = prob
    results, broken = run_every_method(M, q, feasible=False)
    assert broken == []
    infeasibility_claims_carry_a_proof(M, q, results)
    res = results["auto"]
    if results["lemke"].status == lcp.INFEASIBLE:
        assert res.status == lcp.INFEASIBLE and res.path == ("lemke",)


@_settings("zmatrix")
@given(zmatrix_infeasible())
def test_zmatrix_family(prob):
    M, q = prob
    results, broken = run_every_method(M, q, feasible=False)
    assert broken == []
    infeasibility_claims_carry_a_proof(M, q, results)


@_settings("monotone")
@given(monotone_feasible())
def test_monotone_family(prob):
    M, q = prob
    results, broken = run_every_method(M, q, feasible=True)
    assert broken == []
    # copositive-plus and feasible: Lemke's theorem says it solves
    for method in ("lemke", "auto"):
        assert results[method].success, f"{method}: {results[method].message}"
