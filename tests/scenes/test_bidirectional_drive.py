"""The two-rod bidirectional drive: its equations against independent derivations.

Layer 1: M, h, gaps, contact Jacobians and drift terms against a symbolic
Lagrangian (sympy) written from the geometry of both rods (centres, tips,
hinge spacing), differentiated symbolically. Layer 2: with one rod removed
the equations are exactly the paper's single-rod scene (rod ``b`` under the
mirror map ``u2 -> -u2``).
"""

import math

import numpy as np
import pytest
import sympy as sp

from moreau.errors import InputError
from moreau.scenes.bidirectional_drive import (BidirectionalDrive, BidirectionalDriveParams,
                                               params_from_kwargs)
from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams

rng = np.random.default_rng(2026)


def random_params(**kw):
    phi0 = rng.uniform(0.3, 1.3)
    lmax = 1e-3 * math.sin(phi0) / 2
    base = dict(phi0=phi0, mu=rng.uniform(0.05, 0.6), load=rng.uniform(-1e-3, 1e-3),
                m2=rng.uniform(1e-4, 1e-2), k=rng.uniform(1e3, 1e5),
                x10_a=rng.uniform(0.1, 0.9) * lmax, x10_b=rng.uniform(0.1, 0.9) * lmax,
                phase=rng.uniform(-math.pi, math.pi))
    base.update(kw)
    return BidirectionalDriveParams(**base)


def symbolic_model():
    """Equations of motion and contact kinematics from the geometry, dimensionless.

    Lengths over ``l``, time ``tau``, energies over ``m l^2 w^2``; ``d`` is the
    hinge spacing (it must drop out).
    """
    tau, J, P, s0, fL, ua, ub, dl, d = sp.symbols("tau J P s0 fL ua ub delta d", real=True)
    pa, pb, u2 = (sp.Function(n)(tau) for n in ("pa", "pb", "u2"))
    x1a = ua * (1 - sp.cos(tau))
    x1b = ub * (1 - sp.cos(tau - dl))
    ca = sp.Matrix([sp.cos(pa) / 2, x1a + sp.sin(pa) / 2])
    cb = sp.Matrix([d - sp.cos(pb) / 2, x1b + sp.sin(pb) / 2])
    tip_a = sp.Matrix([sp.cos(pa), x1a + sp.sin(pa)])
    tip_b = sp.Matrix([d - sp.cos(pb), x1b + sp.sin(pb)])
    vel = lambda r: r.diff(tau)  # noqa: E731
    T = (sp.Rational(1, 2) * (vel(ca).dot(vel(ca)) + vel(cb).dot(vel(cb)))
         + sp.Rational(1, 24) * (pa.diff(tau) ** 2 + pb.diff(tau) ** 2)
         + J / 2 * u2.diff(tau) ** 2)
    Vp = P / 2 * ((s0 - sp.sin(pa)) ** 2 + (s0 - sp.sin(pb)) ** 2)
    L = T - Vp - fL * u2
    q = [pa, pb, u2]
    # rotor surface at height s0 above each hinge; the gap is surface minus tip height
    gN = [s0 - tip_a[1], s0 - tip_b[1]]
    gT = [u2 - tip_a[0], u2 - tip_b[0]]
    Q = sp.symbols("q0:3", real=True)
    Vs = sp.symbols("v0:3", real=True)
    A = sp.symbols("a0:3", real=True)
    subs = {}
    for qi, Qi, Vi, Ai in zip(q, Q, Vs, A):
        subs[qi.diff(tau, 2)] = Ai
        subs[qi.diff(tau)] = Vi
    subs_q = {qi: Qi for qi, Qi in zip(q, Q)}

    def plain(expr):
        return sp.simplify(expr.subs(subs).subs(subs_q))

    eqs = [plain(sp.diff(L.diff(qi.diff(tau)), tau) - L.diff(qi)) for qi in q]
    M = sp.Matrix([[sp.diff(e, a) for a in A] for e in eqs])
    h = -sp.Matrix([e.subs({a: 0 for a in A}) for e in eqs])
    rows = {}
    for name, g in (("N", gN), ("T", gT)):
        Wm = sp.Matrix([[plain(sp.diff(gi, qj)) for qj in q] for gi in g])
        w = sp.Matrix([plain(sp.diff(gi, tau) - sum(sp.diff(gi, qj) * qj.diff(tau) for qj in q))
                       for gi in g])
        acc = sp.Matrix([plain(sp.diff(gi, tau, 2)) for gi in g])
        wbar = acc.subs({a: 0 for a in A})
        rows[name] = (Wm, w, wbar)
    args = (tau, J, P, s0, fL, ua, ub, dl, d, Q, Vs)
    f = lambda e: sp.lambdify(args, e, "numpy")  # noqa: E731
    return {"M": f(M), "h": f(h), "gN": f(sp.Matrix([plain(g) for g in gN])),
            "WN": f(rows["N"][0]), "wN": f(rows["N"][1]), "wNbar": f(rows["N"][2]),
            "WT": f(rows["T"][0]), "wT": f(rows["T"][1]), "wTbar": f(rows["T"][2])}


@pytest.fixture(scope="module")
def model():
    return symbolic_model()


@pytest.mark.parametrize("trial", range(12))
def test_scene_matches_symbolic_lagrangian(model, trial):
    p = random_params()
    sc = BidirectionalDrive(p, frequency=float(np.exp(rng.uniform(np.log(10), np.log(5000)))))
    q = np.array([rng.uniform(0.2, 1.3), rng.uniform(0.2, 1.3), rng.normal()])
    v = rng.normal(size=3) * 0.05
    tau = rng.uniform(0, 2 * math.pi)
    args = (tau, sc.J, sc.P, sc.sin_phi0, sc.fL, sc.u10[0], sc.u10[1], p.phase,
            rng.uniform(0.5, 3.0), q, v)
    ev = {k: np.array(fn(*args), dtype=float) for k, fn in model.items()}
    scale = 1.0 + sc.P
    np.testing.assert_allclose(sc.mass(q), ev["M"], rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(sc.forces(q, v, tau), ev["h"].ravel(), rtol=1e-11,
                               atol=1e-13 * scale)
    np.testing.assert_allclose(sc.gaps(q, tau), ev["gN"].ravel(), rtol=0, atol=1e-14)
    WN, wN, WT, wT = sc.contact_jacobians(q, tau)
    wNb, wTb = sc.contact_drift(q, v, tau)
    np.testing.assert_allclose(WN, ev["WN"], atol=1e-15)
    np.testing.assert_allclose(wN, ev["wN"].ravel(), atol=1e-15)
    np.testing.assert_allclose(WT, ev["WT"], atol=1e-15)
    np.testing.assert_allclose(wT, ev["wT"].ravel(), atol=1e-15)
    np.testing.assert_allclose(wNb, ev["wNbar"].ravel(), atol=1e-14)
    np.testing.assert_allclose(wTb, ev["wTbar"].ravel(), atol=1e-14)


def test_force_jacobian_matches_finite_differences():
    sc = BidirectionalDrive(random_params(), frequency=300.0)
    q, v, t = np.array([0.7, 0.9, 0.1]), np.array([0.01, -0.02, 0.0]), 1.3
    K, C = sc.force_jacobians(q, v, t)
    hstep = 1e-6
    Kfd = np.column_stack([(sc.forces(q + hstep * e, v, t) - sc.forces(q - hstep * e, v, t))
                           / (2 * hstep) for e in np.eye(3)])
    np.testing.assert_allclose(K, Kfd, rtol=1e-7, atol=1e-7 * (1 + sc.P))
    assert not C.any()


@pytest.mark.parametrize("trial", range(8))
def test_one_rod_removed_is_the_paper_scene(trial):
    """Deleting rod b (its angle and contact) leaves FrictionDrive; rod b alone is its mirror."""
    p = random_params()
    f = float(rng.uniform(15, 3000))
    sc = BidirectionalDrive(p, frequency=f)
    q = np.array([rng.uniform(0.2, 1.3), rng.uniform(0.2, 1.3), rng.normal()])
    v = rng.normal(size=3) * 0.05
    tau = rng.uniform(0, 2 * math.pi)
    M, h = sc.mass(q), sc.forces(q, v, tau)
    g = sc.gaps(q, tau)
    WN, wN, WT, wT = sc.contact_jacobians(q, tau)
    wNb, wTb = sc.contact_drift(q, v, tau)
    # rod a: coordinates (phi_a, u2), contact 0
    fa = FrictionDrive(p.rod("a"), frequency=f)
    ia = [0, 2]
    qa, va = q[ia], v[ia]
    WNa, wNa, WTa, wTa = fa.contact_jacobians(qa, tau)
    assert np.array_equal(M[np.ix_(ia, ia)], fa.mass(qa))
    assert np.array_equal(h[ia], fa.forces(qa, va, tau))
    assert g[0] == fa.gaps(qa, tau)[0]
    assert np.array_equal(WN[0, ia], WNa[0]) and WN[0, 1] == 0.0 and wN[0] == wNa[0]
    assert np.array_equal(WT[0, ia], WTa[0]) and WT[0, 1] == 0.0 and wT[0] == wTa[0]
    wNba, wTba = fa.contact_drift(qa, va, tau)
    assert wNb[0] == wNba[0] and wTb[0] == wTba[0]
    # the rods are coupled through the rotor only: no inertial or elastic cross terms
    assert M[0, 1] == M[1, 0] == 0.0
    # rod b: coordinates (phi_b, u2), contact 1, the single-rod scene mirrored (u2 -> -u2),
    # with the stator phase shifted by delta and the load mirrored too
    fb = FrictionDrive(p.rod("b").with_(load=-p.load), frequency=f)
    ib = [1, 2]
    mirror = np.array([1.0, -1.0])
    qb, vb, tb = q[ib] * mirror, v[ib] * mirror, tau - p.phase
    WNb_, wNb_, WTb_, wTb_ = fb.contact_jacobians(qb, tb)
    assert np.array_equal(M[np.ix_(ib, ib)], fb.mass(qb))
    np.testing.assert_allclose(h[ib], fb.forces(qb, vb, tb) * mirror, rtol=1e-14, atol=1e-14)
    assert g[1] == pytest.approx(fb.gaps(qb, tb)[0], abs=1e-15)
    np.testing.assert_allclose(WN[1, ib], WNb_[0] * mirror, atol=0)
    assert wN[1] == pytest.approx(wNb_[0], abs=1e-16)
    # a mirrored slip velocity is the negative of the single rod's: T rows flip sign
    np.testing.assert_allclose(WT[1, ib], -WTb_[0] * mirror, atol=0)
    wNbb, wTbb = fb.contact_drift(qb, vb, tb)
    assert wNb[1] == pytest.approx(wNbb[0], abs=1e-15)
    assert wTb[1] == pytest.approx(-wTbb[0], abs=1e-15)


def test_rest_state_is_on_both_contact_manifolds():
    sc = BidirectionalDrive(random_params(), frequency=185.0)
    for tau in (0.0, 1.0, 4.0):
        q, v = sc.rest_state(tau)
        assert np.allclose(sc.gaps(q, tau), 0.0, atol=1e-15)
        vN, _ = sc.contact_velocities(q, v, tau)
        assert np.allclose(vN, 0.0, atol=1e-15)


def test_dimensionless_constants_and_si():
    sc = BidirectionalDrive(BidirectionalDriveParams(x10_b=1e-6, phase=0.5), frequency=20.0)
    w = 2 * math.pi * 20.0
    assert sc.J == pytest.approx(100.0)
    assert sc.P == pytest.approx(1e4 / (2e-5 * w * w), rel=1e-14)
    assert sc.u10.tolist() == pytest.approx([2e-3, 1e-3])
    assert sc.displacement_to_si(1.0) == pytest.approx(1e-3)
    assert sc.velocity_to_si(1.0) == pytest.approx(1e-3 * w)
    assert sc.force_to_si(1.0) == pytest.approx(2e-5 * 1e-3 * w * w)


def test_frictionless_has_no_tangential_rows():
    sc = BidirectionalDrive(BidirectionalDriveParams(mu=0.0))
    q, v = sc.rest_state()
    WN, wN, WT, wT = sc.contact_jacobians(q, 0.0)
    assert WN.shape == (2, 3) and WT.shape == (0, 3) and wT.shape == (0,)
    assert sc.contact_drift(q, v, 0.0)[1].shape == (0,)


def test_from_single_and_kwargs():
    p = BidirectionalDriveParams.from_single(FrictionDriveParams(mu=0.3), x10_b=1e-6, phase=1.0)
    assert (p.mu, p.x10_a, p.x10_b, p.phase) == (0.3, 2e-6, 1e-6, 1.0)
    assert params_from_kwargs(mu=0.2, x10_b=None).x10_b == 2e-6
    with pytest.raises(InputError, match="unknown parameter"):
        params_from_kwargs(x10=1e-6)


@pytest.mark.parametrize("kw, match", [
    (dict(m=-1.0), r"`m` must be > 0"),
    (dict(mu=-0.1), r"`mu` must be >= 0"),
    (dict(phi0=1.6), r"`phi0` must be in the open interval"),
    (dict(x10_a=-1e-6), r"`x10_a` must be >= 0"),
    (dict(x10_b=1e-3), r"`x10_b` must be < length\*sin\(phi0\)/2"),
    (dict(phase=float("nan")), r"`phase` must be finite"),
    (dict(restitution=2.0), r"`restitution` must be in"),
])
def test_bad_parameters(kw, match):
    with pytest.raises(InputError, match=match):
        BidirectionalDriveParams(**kw)


def test_bad_scene_arguments():
    with pytest.raises(InputError, match="`frequency` must be > 0"):
        BidirectionalDrive(frequency=0.0)
    with pytest.raises(InputError, match="`params` must be a BidirectionalDriveParams"):
        BidirectionalDrive(FrictionDriveParams())
    with pytest.raises(InputError, match="`x10_b` must be > 0 for a single-rod scene"):
        BidirectionalDrive(BidirectionalDriveParams(x10_b=0.0)).single_rod("b")
    with pytest.raises(InputError, match="`which` must be 'a' or 'b'"):
        BidirectionalDriveParams().rod("c")
