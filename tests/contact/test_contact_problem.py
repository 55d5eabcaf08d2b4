"""The contact-problem object: the same impulses as the function it replaced, its layout, its checks."""

import numpy as np
import pytest

from _contact_reference import old_solve, random_problem
from moreau.contact import (ContactProblem, from_fclib, get_solver, register_solver, solve,
                            solver_names, to_fclib)
from moreau.errors import InputError
from moreau.integrators.contact_problem import new_contact_counters, solve_contact_problem
from moreau.lcp import build_friction_lcp, lcp_violation


@pytest.mark.parametrize("lcp_method", ["auto", "lemke"])
def test_the_object_gives_the_old_functions_impulses_bit_for_bit(lcp_method):
    rng = np.random.default_rng(35)
    for trial in range(60):
        nc = 1 + trial % 4
        W, U, mu, e, vN = random_problem(rng, nc)
        (p0, pN0, pT0), c0 = old_solve(W, U, mu, e, vN, lcp_method)
        sol = solve(ContactProblem(W, U, mu, e, vN), lcp_method)
        c1 = new_contact_counters()
        p1, pN1, pT1 = solve_contact_problem(W, U, mu, e, vN, lcp_method=lcp_method, counters=c1)
        for old, new in ((p0, sol.p), (pN0, sol.pN), (pT0, sol.pT), (p0, p1), (pN0, pN1), (pT0, pT1)):
            assert new.shape == old.shape and np.array_equal(new, old), (trial, old, new)
        for key in ("lcp_solves", "direct_solves", "pivots", "fallbacks", "max_residual"):
            assert c1[key] == c0[key], (trial, key)
        assert sol.success and sol.residual == c0["max_residual"]
        # and it is a solution: certified on the friction LCP of the caller's data
        Ml, ql, layout = build_friction_lcp(W, U, mu, e, vN)
        z = np.zeros(layout.size)
        z[layout.normal] = sol.pN
        fr = layout.frictional
        z[layout.tplus[fr]] = np.maximum(sol.pT[fr], 0.0)
        z[layout.tminus[fr]] = np.maximum(-sol.pT[fr], 0.0)
        z[layout.beta[fr]] = np.abs((U + W @ sol.p)[nc:])
        assert lcp_violation(Ml, ql, z) <= 1e-9


def test_a_frictionless_contact_brings_no_tangential_row():
    mu = np.array([0.5, 0.0, 0.3])
    rng = np.random.default_rng(1)
    J = rng.standard_normal((5, 6))
    W = J @ J.T
    pb = ContactProblem(W, -np.ones(5), mu)
    assert (pb.n_contacts, pb.n_frictional, pb.n_rows) == (3, 2, 5)
    assert pb.frictional.tolist() == [0, 2] and pb.tangential_rows == slice(3, 5)
    with pytest.raises(InputError, match=r"`W` must have shape \(5, 5\).*one per contact with mu > 0"):
        ContactProblem(np.eye(6), -np.ones(6), mu)
    sol = solve(pb)
    assert sol.success and sol.p.shape == (5,) and sol.pT[1] == 0.0
    assert sol.pT[[0, 2]].tolist() == sol.p[3:].tolist()
    # FCLib's layout gives the frictionless contact a row whose cone (mu = 0) holds r_T = 0
    lp = to_fclib(pb)
    assert lp.W.shape == (6, 6) and lp.mu.tolist() == mu.tolist()
    assert lp.W[3, 3] == 1.0 and not np.any(lp.W[3, [0, 1, 2, 4, 5]])


def test_the_fclib_layout_gives_the_same_velocities():
    rng = np.random.default_rng(2)
    W, U, mu, e, vN = random_problem(rng, 4)
    pb = ContactProblem(W, U, mu, e, vN)
    sol = solve(pb)
    lp = to_fclib(pb)
    r = np.zeros(2 * pb.n_contacts)
    r[0::2] = sol.pN
    r[1::2] = sol.pT
    assert np.array_equal(from_fclib(pb, r), sol.p)
    Uf = lp.W @ r + lp.q
    U1 = pb.velocities(sol.p)
    nc = pb.n_contacts
    assert np.allclose(Uf[0::2], U1[:nc] + pb.impact_shift(), rtol=0, atol=1e-13)
    assert np.allclose(Uf[1::2][pb.frictional], U1[nc:], rtol=0, atol=1e-13)
    with pytest.raises(InputError, match="`problem` has n_eq = 1"):
        to_fclib(ContactProblem(np.eye(2), [0.0, -1.0], [0.0], n_eq=1))


BAD = [
    (dict(mu=[-0.1]), "`mu` must be >= 0"),
    (dict(e=1.5), r"`e` must lie in \[0, 1\]"),
    (dict(e=[0.1, 0.2]), "`e` must be a scalar or have one entry per contact"),
    (dict(W=[[np.nan, 0.0], [0.0, 1.0]]), "`W` must be finite"),
    (dict(W=np.ones(4)), "`W` must be 2-D"),
    (dict(u_free=[1.0, 2.0, 3.0]), r"`u_free` must have shape \(2,\)"),
    (dict(vN_pre=[1.0, 2.0]), "`vN_pre` must have one entry per contact"),
    (dict(n_eq=-1), "`n_eq` must be an integer >= 0"),
    (dict(n_eq=True), "`n_eq` must be an integer >= 0"),
    (dict(eq_target=[1.0]), r"`eq_target` must have one entry per equality row \(0\)"),
    (dict(mu="a"), "`mu` must be an array of real numbers"),
    # one frictional contact: the friction LCP has 4 variables (p_N, t+, t-, beta)
    (dict(warm=[4]), r"`warm` must hold distinct indices in \[0, 4\)"),
    (dict(warm=[0, 0]), r"`warm` must hold distinct indices in \[0, 4\)"),
    (dict(warm=[0.5]), "`warm` must be a 1-d sequence of integer indices"),
    (dict(warm=[[0]]), "`warm` must be a 1-d sequence of integer indices"),
    (dict(W=np.eye(3), u_free=[0.0, -1.0, 1.0], n_eq=1, warm=[0]),
     "`warm` is a support of the friction LCP, which has no equality rows"),
]


@pytest.mark.parametrize("change, message", BAD)
def test_bad_input_is_named(change, message):
    args = dict(W=np.eye(2), u_free=[-1.0, 1.0], mu=[0.5])
    args.update(change)
    with pytest.raises(InputError, match=message):
        ContactProblem(**args)


def test_solve_refuses_by_name():
    pb = ContactProblem(np.eye(3), [-1.0, -1.0, 0.0], [0.0, 0.4])
    with pytest.raises(InputError, match="`method` must be one of 'apgd', 'auto', 'closed-form'"):
        solve(pb, "simplex")
    with pytest.raises(InputError, match="`method` 'closed-form' solves at most 1 contact"):
        solve(pb, "closed-form")
    with pytest.raises(InputError, match="`warm` is not an option of method 'lemke'"):
        solve(pb, "lemke", warm=True)
    eq = ContactProblem(np.eye(2), [0.0, -1.0], [0.0], n_eq=1)
    with pytest.raises(InputError, match="`method` 'lemke' solves no equality rows"):
        solve(eq, "lemke")
    with pytest.raises(InputError, match="`name` 'qp' is registered already"):
        register_solver("qp", lambda problem: None)
    assert {"auto", "closed-form", "lemke", "qp", "mlcp"} <= set(solver_names())
    assert get_solver("mlcp").equality_rows and not get_solver("lemke").equality_rows


def test_the_problem_is_frozen_and_its_arrays_read_only():
    W = np.eye(2)
    pb = ContactProblem(W, [-1.0, 1.0], [0.5])
    W[0, 0] = 5.0                      # a copy was taken
    assert pb.W[0, 0] == 1.0
    with pytest.raises(ValueError):
        pb.W[0, 0] = 2.0
    with pytest.raises(AttributeError):
        pb.n_eq = 2


def test_an_unsolved_problem_says_so():
    # Lemke stopped by a pivot limit of 1: the solution says so, the schemes' function raises
    rng = np.random.default_rng(3)
    W, U, mu, e, vN = random_problem(rng, 3, frictionless=0.0)
    U[:3] = -1.0
    sol = solve(ContactProblem(W, U, mu, e, vN), "lemke", max_iter=1)
    assert sol.status == "max-iter" and not sol.success and "Iteration limit" in sol.message


def test_an_empty_problem_is_solved_by_every_method():
    for method in ("auto", "closed-form", "lemke", "mlcp"):
        sol = solve(ContactProblem(np.zeros((0, 0)), np.zeros(0), np.zeros(0)), method)
        assert sol.success and sol.p.shape == (0,) and sol.method == "none"


def test_a_warm_support_is_kept_under_its_key_and_only_the_last():
    # two frictional contacts pressed: the friction LCP's support is remembered under the
    # caller's key, and a problem under another key starts without it
    W = np.array([[2.0, 0.5, 0.1, 0.0], [0.5, 2.0, 0.0, 0.1],
                  [0.1, 0.0, 1.0, 0.2], [0.0, 0.1, 0.2, 1.0]])
    U = np.array([-1.0, -1.0, 0.3, -0.2])
    mu, e, vN = np.array([0.5, 0.5]), np.zeros(2), np.array([-1.0, -1.0])
    warm, c = {}, new_contact_counters()
    p, _, _ = solve_contact_problem(W, U, mu, e, vN, counters=c, warm=warm, warm_key=(0, 1))
    M, q, _ = build_friction_lcp(W, U, mu, e, vN)
    (key, support), = warm.items()
    assert key == (0, 1)
    z = np.zeros(M.shape[0])
    z[support] = np.linalg.solve(M[np.ix_(support, support)], -q[support])
    assert lcp_violation(M, q, z) <= 1e-12
    solve_contact_problem(W[:2, :2], U[:2], np.zeros(2), e, vN, counters=c, warm=warm,
                          warm_key=(5,))
    assert list(warm) == [(5,)]


def _h(values):
    return np.array([float.fromhex(v) for v in values])


#: a step of the bidirectional drive's generic Moreau–Jean run (h = 2 pi / 1000, from the
#: scene's initial state, about its 50th step): both rods stick, each at the friction
#: cone's edge (p_T = mu p_N), a tie on which Lemke's path would be finished in exact
#: arithmetic
TIED = dict(
    W=np.array([_h(r) for r in (
        ["0x1.77d289444922fp+0", "0x0.0p+0", "-0x1.77c380c1d4952p+0", "0x0.0p+0"],
        ["0x0.0p+0", "0x1.77d289444922fp+0", "0x0.0p+0", "0x1.77c380c1d4952p+0"],
        ["-0x1.77c380c1d4952p+0", "0x0.0p+0", "0x1.7a43d502476dfp+0", "0x1.47ae147ae147bp-7"],
        ["0x0.0p+0", "0x1.77c380c1d4952p+0", "0x1.47ae147ae147bp-7", "0x1.7a43d502476dfp+0"])]),
    U=_h(["-0x1.a70f715c37f7cp-13", "-0x1.a70f715c38028p-13", "-0x1.1c6655315f3f3p-12",
          "0x1.1c6655315f39bp-12"]),
    mu=np.full(2, 0.1), e=np.zeros(2), vN=_h(["0x1.033bf9f520000p-29", "0x1.033bf9ea20000p-29"]))


def test_a_warm_support_solves_where_lemke_would_go_exact():
    # with the support of the step before, "auto" takes that support's point (no pivot, no
    # QP) and counts a warm start; without, the QP's answer (a fallback). Both are checked
    # on the data
    from moreau.lcp import lemke
    W, U, mu, e, vN = TIED["W"], TIED["U"], TIED["mu"], TIED["e"], TIED["vN"]
    M, q, _ = build_friction_lcp(W, U, mu, e, vN)
    assert lemke._solve(M, q, None, None, True, None, True) is None     # the hand-over
    c = new_contact_counters()
    warm = {(0, 1): np.array([0, 1, 3, 4, 6, 7])}
    p, pN, pT = solve_contact_problem(W, U, mu, e, vN, counters=c, warm=warm, warm_key=(0, 1))
    assert c["warm_starts"] == 1 and c["fallbacks"] == 0 and c["pivots"] == 0
    np.testing.assert_allclose(np.abs(pT), mu * pN, rtol=1e-14)     # at the cone's edge
    sol = solve(ContactProblem(W, U, mu, e, vN, warm=[0, 1, 3, 4, 6, 7]), "auto")
    assert sol.lcp.path == ("lemke", "support") and sol.lcp.pivots == 0
    assert lcp_violation(M, q, sol.lcp.z) <= lemke.DEFAULT_TOL
    np.testing.assert_array_equal(sol.p, p)
    c0 = new_contact_counters()
    p0, _, _ = solve_contact_problem(W, U, mu, e, vN, counters=c0)
    assert c0["fallbacks"] == 1 and c0.get("warm_starts", 0) == 0
    np.testing.assert_allclose(p0, p, rtol=0, atol=1e-9 * np.abs(p).max())
