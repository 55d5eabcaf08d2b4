"""Compiled (numba) form of every shipped scene's model, for the compiled Moreau–Jean loop.

A scene hands its model to compiled code as a :class:`CompiledModel`: an
integer ``kind`` naming its equations below and a float vector ``par`` of its
parameters. One compiled time stepper then serves every scene
(:mod:`moreau.integrators._mj_kernels`): the few functions here dispatch on
``kind``, so the stepper is compiled (and cached on disk) once, not once per
scene. Passing the model as numba first-class functions would specialise the
stepper per function object, and such specialisations are not found again in
numba's on-disk cache.

Adding a scene: give it a new ``kind``, add its branch to each function
below, and a ``compiled_model()`` method returning ``CompiledModel(kind,
par, ...)``. The stepper's on-disk cache is tied to the contents of this
module (:data:`moreau.integrators._mj_kernels.KERNEL_SOURCES`), so an edit
here recompiles it on the next run; a scene model kept in another file must
be added to that list.

The Python :class:`~moreau.scenes.base.Scene` methods stay the definition;
the formulas here are transcriptions of them, and
``tests/integrators/test_compiled_engine.py`` checks every function against
its Python counterpart to ``1e-12``. Layout of the outputs (the caller
zero-fills them once; a model writes the same entries on every call and
leaves the structural zeros alone, so that the stepper does not clear arrays
on every step):

* ``mass_fn(kind, par, q, M)``: ``M`` (ndof, ndof).
* ``dynamics_fn(kind, par, q, v, t, D, need_jac)``: ``D`` (ndof, 1 + 2 ndof)
  holds the forces ``h`` in column 0 and, when ``need_jac``, ``K = dh/dq`` in
  columns ``1 .. ndof`` and ``C = dh/dv`` after them (scenes with
  ``has_jacobians = False`` never write them).
* ``contact_fn(kind, par, q, t, G, need_gap, need_T=True)``: row ``i`` of ``G``
  (nc, 3 + 2 ndof) is ``(g_i, wN_i, wT_i, WN_i, WT_i)``: the gap (when
  ``need_gap``), the rheonomic terms, the normal row and one tangential row
  *per contact*; the stepper reads a contact's tangential entries only when
  its ``mu > 0``. (The Python interface returns tangential rows of the
  frictional contacts only.) With ``need_T=False`` only ``wN`` and ``WN`` are
  written.
* ``gaps_fn(kind, par, q, t, G)``: column 0 of ``G``.
* ``drift_fn(kind, par, q, v, t, Dr)``: ``Dr`` (nc, 2) = ``(wNbar, wTbar)``.
* ``step_fn(...)``: all that one Moreau–Jean step reads at its start state,
  in one call (the time stepper uses this one).

The outputs are packed into one array per function so that each inlined
call carries few array arguments (numba reference-counts them).
"""

import math
from collections import namedtuple

import numpy as np
from numba import njit

__all__ = ["CompiledModel", "mass_fn", "dynamics_fn", "contact_fn", "gaps_fn", "drift_fn", "step_fn",
           "fused",
           "FRICTION_DRIVE", "BOUNCING_BALL", "SLIDING_BLOCK", "PAINLEVE_ROD",
           "STICK_SLIP_MOTOR", "BIDIRECTIONAL_DRIVE", "SLIDING_BOX", "check_compiled_model"]

#: the model of a scene for compiled code. ``kind``: which equations;
#: ``par``: float64 parameters; ``const_mass``: ``M`` does not depend on ``q``;
#: ``has_jacobians``: ``dh/dq`` or ``dh/dv`` is not identically zero.
CompiledModel = namedtuple("CompiledModel", ["kind", "par", "ndof", "ncontacts", "const_mass",
                                             "has_jacobians"])

FRICTION_DRIVE = 1
BOUNCING_BALL = 2
SLIDING_BLOCK = 3
PAINLEVE_ROD = 4
STICK_SLIP_MOTOR = 5
BIDIRECTIONAL_DRIVE = 6
SLIDING_BOX = 7

TWO_PI = 2.0 * math.pi


# -- the rod of a friction drive ----------------------------------------------------------
# Both drives are built from one rod pressed by its spring on the rotor (the paper's model;
# the two-rod drive mirrors the second rod). These scalar pieces take the sines and cosines
# already evaluated, so that a caller evaluating several outputs at one state (step_fn)
# computes each transcendental once, and each formula is written once for both drives.
# Rod j at angle phi (s = sin phi, c = cos phi), base motion u1 = u10 (1 - cos tau') with
# tau' = tau - delta (st = sin tau', ct = cos tau'), rotor coordinate `rotor`:
#   h_j = P c (sin phi0 - s) - u1''/2 c,   dh_j/dphi = P (-s (sin phi0 - s) - c^2) + u1''/2 s
#   g = sin phi0 - s - u1,   WN = -c e_j,   wN = -u1',   WT = sgn s e_j + e_rotor,   wT = 0


@njit(cache=True, inline="always")
def _rod_gap(sphi0, u10, s, ct):
    return sphi0 - s - u10 * (1.0 - ct)


@njit(cache=True, inline="always")
def _rod_forces(D, j, P, sphi0, u10, s, c, ct, need_jac):
    ddu1 = u10 * ct
    spring = sphi0 - s
    D[j, 0] = P * c * spring - 0.5 * ddu1 * c
    if need_jac:
        D[j, 1 + j] = P * (-s * spring - c * c) + 0.5 * ddu1 * s
    return D.size


@njit(cache=True, inline="always")
def _rod_rows(G, r, j, rotor, n, sgn, u10, s, c, st, need_T):
    # contact row r of the rod with angle q[j] (layout of contact_fn)
    G[r, 1] = -u10 * st
    G[r, 3 + j] = -c
    if need_T:
        G[r, 3 + n + j] = sgn * s
        G[r, 3 + n + rotor] = 1.0
    return G.size


# -- stick-slip motor drives -------------------------------------------------------------
# par: [fL, n, drive (0 sine, 1 sawtooth), b, psi, nseg, starts[4], acc[4], vel[4], pos[4]]

@njit(cache=True, inline="always")
def _motor_drive(par, t):
    if par[2] == 0.0:
        b = par[3]
        a2 = 2.0 * t + par[4]
        return (math.sin(t) + b * math.sin(a2), math.cos(t) + 2.0 * b * math.cos(a2),
                -math.sin(t) - 4.0 * b * math.sin(a2))
    nseg = int(par[5])
    # Python's float modulo, as np.mod in the Python model
    tm = t % TWO_PI
    k = -1
    for i in range(nseg):
        if par[6 + i] <= tm:
            k = i
    if k < 0:
        k = nseg - 1
    st = par[6 + k]
    dt = tm - st if tm >= st else tm + TWO_PI - st
    a = par[10 + k]
    v0 = par[14 + k]
    return par[18 + k] + v0 * dt + 0.5 * a * dt * dt, v0 + a * dt, a


# -- dispatchers -------------------------------------------------------------------------
#
# Each function below ends by "touching" its array arguments (their sizes are
# returned and ignored). Numba inlines these functions into the stepper and
# reference-counts every array argument there; without a use after the
# ``kind`` branches merge, each branch releases the arrays separately and
# LLVM's reference-count pruning cannot pair those releases with the single
# acquire, which left ~20 atomic increments and decrements in every step.


@njit(cache=True, inline="always")
def _touch3(a, b, c):
    return a.size + b.size + c.size


@njit(cache=True, inline="always")
def mass_fn(kind, par, q, M):
    if kind == FRICTION_DRIVE:
        M[0, 0] = 1.0 / 3.0
        M[1, 1] = par[0]
    elif kind == BIDIRECTIONAL_DRIVE:
        M[0, 0] = 1.0 / 3.0
        M[1, 1] = 1.0 / 3.0
        M[2, 2] = par[0]
    elif kind == PAINLEVE_ROD:
        M[0, 0] = 1.0
        M[1, 1] = 1.0
        M[2, 2] = 1.0 / 3.0
    elif kind == SLIDING_BOX:
        M[0, 0] = 1.0
        M[1, 1] = 1.0
        M[2, 2] = par[2]
    else:
        for i in range(M.shape[0]):
            M[i, i] = 1.0
    return _touch3(par, q, M)


@njit(cache=True, inline="always")
def dynamics_fn(kind, par, q, v, t, D, need_jac):
    # D[i, 0] = h_i, D[i, 1 + j] = dh_i/dq_j, D[i, 1 + n + j] = dh_i/dv_j
    if kind == FRICTION_DRIVE:
        # par: J, P, u10, fL, sin_phi0
        _rod_forces(D, 0, par[1], par[4], par[2], math.sin(q[0]), math.cos(q[0]), math.cos(t),
                    need_jac)
        D[1, 0] = -par[3]
    elif kind == BIDIRECTIONAL_DRIVE:
        # par: J, P, sin_phi0, fL, u10a, u10b, delta_a, delta_b
        for r in range(2):
            _rod_forces(D, r, par[1], par[2], par[4 + r], math.sin(q[r]), math.cos(q[r]),
                        math.cos(t - par[6 + r]), need_jac)
        D[2, 0] = -par[3]
    elif kind == BOUNCING_BALL:
        D[0, 0] = -1.0
    elif kind == SLIDING_BLOCK:
        # par: sin(alpha), cos(alpha)
        D[0, 0] = par[0]
        D[1, 0] = -par[1]
    elif kind == PAINLEVE_ROD or kind == SLIDING_BOX:
        D[0, 0] = 0.0
        D[1, 0] = -1.0
        D[2, 0] = 0.0
    elif kind == STICK_SLIP_MOTOR:
        D[0, 0] = -par[0]
        D[1, 0] = -par[1]
    return _touch3(par, q, D) + v.size


@njit(cache=True, inline="always")
def gaps_fn(kind, par, q, t, G):
    # G[i, 0] = g_i
    if kind == FRICTION_DRIVE:
        G[0, 0] = _rod_gap(par[4], par[2], math.sin(q[0]), math.cos(t))
    elif kind == BIDIRECTIONAL_DRIVE:
        for r in range(2):
            G[r, 0] = _rod_gap(par[2], par[4 + r], math.sin(q[r]), math.cos(t - par[6 + r]))
    elif kind == BOUNCING_BALL:
        G[0, 0] = q[0] - par[0]
    elif kind == SLIDING_BLOCK or kind == STICK_SLIP_MOTOR:
        G[0, 0] = q[1]
    elif kind == PAINLEVE_ROD:
        G[0, 0] = q[1] - math.sin(q[2])
    elif kind == SLIDING_BOX:
        # par: a, b, inertia; corners at body coordinates (-a, -b), (+a, -b)
        s = math.sin(q[2])
        c = math.cos(q[2])
        G[0, 0] = q[1] - par[0] * s - par[1] * c
        G[1, 0] = q[1] + par[0] * s - par[1] * c
    return _touch3(par, q, G)


@njit(cache=True, inline="always")
def _normal_rows(kind, par, q, t, G):
    # the normal rows only (the stepper's index-set test needs no tangential ones)
    if kind == FRICTION_DRIVE:
        _rod_rows(G, 0, 0, 1, 2, 1.0, par[2], 0.0, math.cos(q[0]), math.sin(t), False)
    elif kind == BIDIRECTIONAL_DRIVE:
        for r in range(2):
            _rod_rows(G, r, r, 2, 3, 1.0 - 2.0 * r, par[4 + r], 0.0, math.cos(q[r]),
                      math.sin(t - par[6 + r]), False)
    elif kind == BOUNCING_BALL:
        G[0, 3] = 1.0
    elif kind == SLIDING_BLOCK or kind == STICK_SLIP_MOTOR:
        G[0, 4] = 1.0
    elif kind == PAINLEVE_ROD:
        G[0, 4] = 1.0
        G[0, 5] = -math.cos(q[2])
    elif kind == SLIDING_BOX:
        s = math.sin(q[2])
        c = math.cos(q[2])
        for i in range(2):
            G[i, 4] = 1.0
            G[i, 5] = (2.0 * i - 1.0) * par[0] * c + par[1] * s
    return _touch3(par, q, G)


@njit(cache=True, inline="always")
def contact_fn(kind, par, q, t, G, need_gap, need_T=True):
    # G[i] = (g_i, wN_i, wT_i, WN_i (n), WT_i (n))
    if need_gap:
        gaps_fn(kind, par, q, t, G)
    if not need_T:
        _normal_rows(kind, par, q, t, G)
    elif kind == FRICTION_DRIVE:
        _rod_rows(G, 0, 0, 1, 2, 1.0, par[2], math.sin(q[0]), math.cos(q[0]), math.sin(t), True)
    elif kind == BIDIRECTIONAL_DRIVE:
        for r in range(2):
            _rod_rows(G, r, r, 2, 3, 1.0 - 2.0 * r, par[4 + r], math.sin(q[r]), math.cos(q[r]),
                      math.sin(t - par[6 + r]), True)
    elif kind == BOUNCING_BALL:
        G[0, 3] = 1.0
    elif kind == SLIDING_BLOCK:
        G[0, 4] = 1.0
        G[0, 5] = 1.0
    elif kind == STICK_SLIP_MOTOR:
        G[0, 4] = 1.0
        G[0, 5] = 1.0
        G[0, 2] = -_motor_drive(par, t)[1]
    elif kind == PAINLEVE_ROD:
        G[0, 4] = 1.0
        G[0, 5] = -math.cos(q[2])
        G[0, 6] = 1.0
        G[0, 8] = math.sin(q[2])
    elif kind == SLIDING_BOX:
        s = math.sin(q[2])
        c = math.cos(q[2])
        a = par[0]
        b = par[1]
        for i in range(2):
            sg = 2.0 * i - 1.0
            G[i, 4] = 1.0
            G[i, 5] = sg * a * c + b * s
            G[i, 6] = 1.0
            G[i, 8] = -sg * a * s + b * c
    return _touch3(par, q, G)


@njit(cache=True, inline="always")
def fused(kind):
    """Whether :func:`step_fn` evaluates this model (the friction drives)."""
    return kind == FRICTION_DRIVE or kind == BIDIRECTIONAL_DRIVE


@njit(cache=True, inline="always")
def step_fn(kind, par, q, v, tk, t1, need_mass, need_gap0, need_f0, need_jac, M, D, D0, G0, G1):
    """Every model output one Moreau–Jean step needs at its start state ``(q_k, v_k)``, in one call.

    Only for the models where that pays (:func:`fused`); the stepper calls
    the separate functions for the others (nesting their ``kind`` dispatch
    in here cost reference counts on every step).

    Writes ``M`` (when ``need_mass``), ``D`` at ``t1`` (Jacobians when
    ``need_jac``), ``D0`` at ``tk`` (forces only, when ``need_f0``), the
    normal rows ``G0`` at ``tk`` (and its gaps when ``need_gap0``) and the
    full contact rows ``G1`` at ``t1``; the same values as the separate
    functions above. For the drives it evaluates each sine and cosine once:
    the separate calls read ``q`` from memory after writing their outputs,
    which the compiler must assume may alias ``q``, so it could not share
    them.
    """
    if kind == FRICTION_DRIVE:
        s = math.sin(q[0])
        c = math.cos(q[0])
        sk = math.sin(tk)
        ck = math.cos(tk)
        s1 = math.sin(t1)
        c1 = math.cos(t1)
        if need_mass:
            mass_fn(kind, par, q, M)
        _rod_forces(D, 0, par[1], par[4], par[2], s, c, c1, need_jac)
        D[1, 0] = -par[3]
        if need_f0:
            _rod_forces(D0, 0, par[1], par[4], par[2], s, c, ck, False)
            D0[1, 0] = -par[3]
        if need_gap0:
            G0[0, 0] = _rod_gap(par[4], par[2], s, ck)
        _rod_rows(G0, 0, 0, 1, 2, 1.0, par[2], s, c, sk, False)
        _rod_rows(G1, 0, 0, 1, 2, 1.0, par[2], s, c, s1, True)
    elif kind == BIDIRECTIONAL_DRIVE:
        if need_mass:
            mass_fn(kind, par, q, M)
        for r in range(2):
            s = math.sin(q[r])
            c = math.cos(q[r])
            sk = math.sin(tk - par[6 + r])
            ck = math.cos(tk - par[6 + r])
            s1 = math.sin(t1 - par[6 + r])
            c1 = math.cos(t1 - par[6 + r])
            sgn = 1.0 - 2.0 * r
            _rod_forces(D, r, par[1], par[2], par[4 + r], s, c, c1, need_jac)
            if need_f0:
                _rod_forces(D0, r, par[1], par[2], par[4 + r], s, c, ck, False)
            if need_gap0:
                G0[r, 0] = _rod_gap(par[2], par[4 + r], s, ck)
            _rod_rows(G0, r, r, 2, 3, sgn, par[4 + r], s, c, sk, False)
            _rod_rows(G1, r, r, 2, 3, sgn, par[4 + r], s, c, s1, True)
        D[2, 0] = -par[3]
        if need_f0:
            D0[2, 0] = -par[3]
    return _touch3(par, q, M) + _touch3(D, D0, G0) + G1.size + v.size


@njit(cache=True)
def drift_fn(kind, par, q, v, t, Dr):
    # Dr[i] = (wNbar_i, wTbar_i)
    if kind == FRICTION_DRIVE:
        w2 = v[0] * v[0]
        Dr[0, 0] = w2 * math.sin(q[0]) - par[2] * math.cos(t)
        Dr[0, 1] = w2 * math.cos(q[0])
    elif kind == BIDIRECTIONAL_DRIVE:
        for r in range(2):
            w2 = v[r] * v[r]
            Dr[r, 0] = w2 * math.sin(q[r]) - par[4 + r] * math.cos(t - par[6 + r])
            Dr[r, 1] = (1.0 - 2.0 * r) * w2 * math.cos(q[r])
    elif kind == STICK_SLIP_MOTOR:
        Dr[0, 1] = -_motor_drive(par, t)[2]
    elif kind == PAINLEVE_ROD:
        w2 = v[2] * v[2]
        Dr[0, 0] = math.sin(q[2]) * w2
        Dr[0, 1] = math.cos(q[2]) * w2
    elif kind == SLIDING_BOX:
        s = math.sin(q[2])
        c = math.cos(q[2])
        w2 = v[2] * v[2]
        for i in range(2):
            sg = 2.0 * i - 1.0
            Dr[i, 0] = w2 * (-sg * par[0] * s + par[1] * c)
            Dr[i, 1] = w2 * (-sg * par[0] * c - par[1] * s)


# -- checking a compiled model against its Python scene ----------------------------------

def evaluate_compiled(model, q, v, t):
    """All compiled model outputs at ``(q, v, t)`` as a dict of arrays (for checks and tests)."""
    n, nc = model.ndof, model.ncontacts
    q = np.ascontiguousarray(q, dtype=float)
    v = np.ascontiguousarray(v, dtype=float)
    t = float(t)
    M = np.zeros((n, n))
    D = np.zeros((n, 1 + 2 * n))
    G = np.zeros((nc, 3 + 2 * n))
    G2 = np.zeros((nc, 3 + 2 * n))
    Dr = np.zeros((nc, 2))
    mass_fn(model.kind, model.par, q, M)
    dynamics_fn(model.kind, model.par, q, v, t, D, True)
    contact_fn(model.kind, model.par, q, t, G, True, True)
    contact_fn(model.kind, model.par, q, t, G2, False, False)
    drift_fn(model.kind, model.par, q, v, t, Dr)
    return {"mass": M, "forces": D[:, 0], "K": D[:, 1:1 + n], "C": D[:, 1 + n:],
            "gaps": G[:, 0], "wN": G[:, 1], "wT": G[:, 2], "WN": G[:, 3:3 + n],
            "WT": G[:, 3 + n:], "WN_normal_only": G2[:, 3:3 + n], "wN_normal_only": G2[:, 1],
            "wNbar": Dr[:, 0], "wTbar": Dr[:, 1]}


def check_compiled_model(scene, q, v, t):
    """Largest difference between ``scene``'s compiled model and its Python methods at ``(q, v, t)``.

    Compares ``M``, ``h``, ``dh/dq``, ``dh/dv``, gaps, ``WN``, ``wN``, the
    tangential rows of the frictional contacts, and the drift terms, each
    relative to ``max(1, |Python value|)``.

    Returns
    -------
    float
        The largest scaled difference; the caller decides what is acceptable.

    Examples
    --------
    >>> from moreau.scenes import BouncingBall
    >>> ball = BouncingBall()
    >>> check_compiled_model(ball, [1.0], [-0.5], 0.3) <= 1e-12
    True
    """
    model = scene.compiled_model()
    c = evaluate_compiled(model, q, v, t)
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    fr = scene.frictional_index
    K, Cj = scene.force_jacobians(q, v, t)
    WN, wN, WT, wT = scene.contact_jacobians(q, t)
    wNb, wTb = scene.contact_drift(q, v, t)
    pairs = [(c["mass"], scene.mass(q)), (c["forces"], scene.forces(q, v, t)),
             (c["K"], K), (c["C"], Cj), (c["gaps"], scene.gaps(q, t)),
             (c["WN"], WN), (c["wN"], wN), (c["WN_normal_only"], WN), (c["wN_normal_only"], wN), (c["WT"][fr], WT), (c["wT"][fr], wT),
             (c["wNbar"], wNb), (c["wTbar"][fr], wTb)]
    worst = 0.0
    for a, b in pairs:
        b = np.asarray(b, dtype=float)
        a = np.asarray(a, dtype=float).reshape(b.shape)
        if b.size:
            worst = max(worst, float(np.max(np.abs(a - b) / np.maximum(1.0, np.abs(b)))))
    return worst
