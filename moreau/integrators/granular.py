r"""Moreau–Jean for a :class:`~moreau.model.granular.DiskSystem`: contacts found every step, NSGS.

The step is the θ-method of :mod:`moreau.integrators.moreau_jean` on disks
with a diagonal mass matrix and constant forces (gravity), from
``(x_k, phi_k, v_k)`` to ``t_{k+1} = t_k + h``::

    v_free  = v_k + h g                       (the forces are constant: θ drops out)
    v_{k+1} = v_free + M^-1 H^T r
    q_{k+1} = q_k + h [θ v_{k+1} + (1 - θ) v_k]

*Contacts.* The broad phase (:meth:`DiskSystem.contacts
<moreau.model.granular.DiskSystem.contacts>`, a uniform grid) lists every
pair within a margin ``2 h v_max + r_min / 20`` of touching (``v_max`` the
largest disk speed), wide enough for every contact of the index set:
contact ``i`` enters the step's problem when its predicted gap is closed,
``g_i + (h/2) u_N,i <= 0`` (``u_N,i`` at ``t_k``; ``u_N >= -2 v_max``), or
when it carried a normal impulse in the step before (the rule of
:mod:`moreau.integrators.moreau_jean`).

*Contact problem.* On the active contacts, with ``H`` their Jacobian at
``q_k`` (rows ``[N_i, T_i]`` interleaved), ``W = H M^-1 H^T`` (CSR, from
:meth:`DiskSystem.delassus <moreau.model.granular.DiskSystem.delassus>`) and
``q = H v_free`` with Newton's impact law folded into the normal rows
(``q_N,i += e_i min(u_N,i(t_k), 0)``), the impulses ``r`` solve FCLib's 2D
frictional contact problem (:mod:`moreau.contact.solvers.nsgs`), warm
started from the last step's impulses of the same pairs of bodies (matched
by :attr:`ContactSet.key <moreau.model.granular.ContactSet.key>`; a new
pair starts at zero).

*Rolling resistance.* Where the system has some (``mu_r > 0``,
:class:`~moreau.model.granular.DiskSystem`), every active contact has a
third row, the relative rolling ``u_R = omega_b - omega_a``, and the
problem is the one of :mod:`moreau.contact.rolling` (``|M| <= mu_r N``, the
couple against the roll), solved by
:func:`~moreau.contact.rolling.solve_nsgs_rolling` with the same warm
start, restart and certified stop; the impulses are interleaved ``[N, T,
R]``. Without, the step is the one above, unchanged.

If the warm-started solve ends above ``tol``, it is run again from zero
(a warm start can stall where the impulses are not unique, a hyperstatic
pile), and that answer replaces it only if it meets ``tol``; ``sweeps``
counts both.

*Status.* Every step records its number of candidate and active contacts,
NSGS's sweeps, its certified residual (the natural map recomputed on the
impulses used) and whether that met ``tol``. A step whose solve ends above
``tol`` is counted in :attr:`GranularResult.unconverged` and makes the run's
``status`` 1 (its ``message`` names the worst residual), or, with
``on_unconverged="stop"``, ends the run there with status -3; it is never
passed silently.
"""

import time

import numpy as np

from .._validate import finite_array, in_closed_interval, positive, positive_int
from ..contact.rolling import solve_nsgs_rolling
from ..contact.solvers.nsgs import solve_nsgs
from ..errors import InputError
from ..model.granular import DiskSystem

__all__ = ["GranularResult", "simulate_disks", "settle"]


class GranularResult:
    """What :func:`simulate_disks` returns.

    Attributes
    ----------
    t : ndarray, shape (k,)
        Sample times.
    x : ndarray, shape (k, N, 2)
        Disk centres.
    phi : ndarray, shape (k, N)
        Disk angles.
    v : ndarray, shape (k, N, 3)
        ``(vx, vy, omega)`` per disk.
    steps : dict of ndarray
        One entry per step taken: ``"t"`` (its end), ``"candidates"``,
        ``"contacts"`` (active), ``"sweeps"``, ``"residual"``,
        ``"converged"``, and ``"wall_impulse"``, shape ``(steps, n_walls, 2)``:
        the sums of the normal and of the tangential impulses the disks
        received from each wall over the step (tangential along ``t = (-n_y, n_x)``).
    status : int
        0 every step's solve met ``tol``; 1 some did not (the run went on:
        :attr:`unconverged`); -3 the run stopped at the first that did not
        (``on_unconverged="stop"``).
    message : str
    unconverged : ndarray of int
        The steps whose solve ended above ``tol``.
    timing : dict
        Seconds spent in the broad phase and contact set, the assembly of
        ``W`` and ``q``, and NSGS; ``"cold_restarts"``, the warm-started
        solves run again from zero.
    impulses : tuple
        ``(ContactSet, r)`` of the last step: its active contacts and their
        impulses (interleaved ``[N, T]``, or ``[N, T, R]`` with rolling
        resistance: ``R`` the couple's impulse on disk ``b``).
    """

    def __init__(self, t, x, phi, v, steps, status, message, timing, impulses, tol):
        self.t, self.x, self.phi, self.v = t, x, phi, v
        self.steps, self.status, self.message = steps, status, message
        self.timing, self.impulses, self.tol = timing, impulses, tol
        self.unconverged = np.flatnonzero(~steps["converged"])

    @property
    def success(self):
        """Whether every step's contact problem was solved to ``tol``."""
        return self.status == 0

    @property
    def max_residual(self):
        return float(np.max(self.steps["residual"], initial=0.0))

    def __repr__(self):
        return f"GranularResult(status={self.status}, {self.message})"


def _speeds(v):
    return np.hypot(v[:, 0], v[:, 1])


def simulate_disks(system, x0, v0, n_steps, h, *, phi0=None, theta=0.5, tol=1e-6,
                   max_sweeps=2000, check_every=4, save_every=1, on_unconverged="report",
                   t0=0.0, callback=None, warm=None):
    """Run Moreau–Jean on ``system`` for ``n_steps`` steps of ``h`` (module docstring).

    Parameters
    ----------
    system : DiskSystem
    x0 : array_like, shape (N, 2)
        Centres; no two disks and no disk and wall may overlap by more than
        ``h`` times their speeds.
    v0 : array_like, shape (N, 3)
        ``(vx, vy, omega)`` per disk.
    n_steps : int
    h : float
        The step, in the system's time.
    phi0 : array_like, shape (N,), optional
        Angles (zero by default).
    theta : float
        In ``[1/2, 1]``.
    tol : float
        NSGS's tolerance on the natural-map residual ``||F(r)|| / (1 + ||q||)``.
    max_sweeps, check_every : int
        NSGS's budget and check interval.
    save_every : int
        Record every ``save_every``-th state (and the last).
    on_unconverged : {"report", "stop"}
        What a step whose solve ends above ``tol`` does: counted and the run
        goes on (status 1), or the run ends there (status -3).
    t0 : float
        The start time.
    callback : callable, optional
        ``callback(k, t, x, v)`` after each step; returning True ends the run
        (status 0, as if its end were reached).
    warm : (ContactSet, ndarray), optional
        The impulses a run ended with (:attr:`GranularResult.impulses`) to
        warm start the first step: a run continued where another stopped
        keeps its contact forces (a static packing's forces are not unique;
        its history picks them). Impulses of a run with rolling resistance
        start one without (their couples dropped), and the other way round
        (couples from zero).

    Returns
    -------
    GranularResult

    Examples
    --------
    A disk dropped onto a rough floor from rest at height 0.2 above touching
    comes to rest on it:

    >>> import numpy as np
    >>> from moreau.model.granular import DiskSystem, HalfPlane
    >>> sys = DiskSystem([0.5], [1.0], walls=[HalfPlane((0, 0), (0, 1))], mu=0.5)
    >>> res = simulate_disks(sys, [[0.0, 0.7]], [[0.0, 0.0, 0.0]], 400, 0.005, theta=1.0)
    >>> res.status, round(float(res.x[-1, 0, 1]), 3), int(res.steps["contacts"][-1])
    (0, 0.5, 1)
    """
    if not isinstance(system, DiskSystem):
        raise InputError(f"`system` must be a DiskSystem, got {type(system).__name__}")
    N = system.n_disks
    x = finite_array("x0", x0, shape=(N, 2)).copy()
    v = finite_array("v0", v0, shape=(N, 3)).copy()
    phi = np.zeros(N) if phi0 is None else finite_array("phi0", phi0, shape=(N,)).copy()
    n_steps = positive_int("n_steps", n_steps)
    h = positive("h", h)
    theta = in_closed_interval("theta", theta, 0.5, 1.0)
    tol = positive("tol", tol)
    save_every = positive_int("save_every", save_every)
    if on_unconverged not in ("report", "stop"):
        raise InputError(f"`on_unconverged` must be 'report' or 'stop', got {on_unconverged!r}")

    dv_free = np.tile(np.array([system.gravity[0], system.gravity[1], 0.0]) * h, N)
    rmin = float(np.min(system.radii))
    t = float(t0)
    ts, xs, phis, vs = [t], [x.copy()], [phi.copy()], [v.copy()]
    rec = {k: [] for k in ("t", "candidates", "contacts", "sweeps", "residual", "converged",
                           "wall_impulse")}
    nw = system.n_walls
    timing = {"broad_phase": 0.0, "assembly": 0.0, "solve": 0.0}
    rolling = system.rolling
    width = 3 if rolling else 2
    prev_keys = np.zeros(0, dtype=np.int64)
    prev_r = np.zeros((0, width))
    if warm is not None and warm[0] is not None:
        prev_keys = np.asarray(warm[0].key, dtype=np.int64)
        given = np.asarray(warm[1], dtype=float).ravel()
        if prev_keys.size == 0 or given.size not in (2 * prev_keys.size, 3 * prev_keys.size):
            if given.size or prev_keys.size:
                raise InputError("`warm` must be (ContactSet, impulses) with two (or three, "
                                 "with rolling resistance) impulses a contact")
        given = given.reshape(prev_keys.size, -1) if prev_keys.size else given.reshape(0, width)
        prev_r = np.zeros((prev_keys.size, width))
        k = min(width, given.shape[1])
        prev_r[:, :k] = given[:, :k]
    closed_keys = prev_keys[prev_r[:, 0] > 0.0]
    status, message = 0, ""
    last = (None, np.zeros(0))
    restarts = 0
    for k in range(n_steps):
        c0 = time.process_time()
        margin = 2.0 * h * float(np.max(_speeds(v), initial=0.0)) + 0.05 * rmin
        cs = system.contacts(x, margin)
        vel = v.reshape(N, 3)
        vb = vel[cs.b, :2]
        va = np.where((cs.a >= 0)[:, None], vel[np.maximum(cs.a, 0), :2], 0.0)
        uN = np.einsum("ij,ij->i", cs.normal, vb - va)
        if system.n_walls:
            uN += system.contact_offsets(cs)[0::2]
        active = (cs.gap + 0.5 * h * uN <= 0.0) | np.isin(cs.key, closed_keys)
        ia = np.flatnonzero(active)
        act = type(cs)(*(f[ia] for f in cs))
        c1 = time.process_time()
        vflat = v.ravel()
        v_free = vflat + dv_free
        na = ia.size
        if na:
            H = system.jacobian(act, rolling=True) if rolling else system.jacobian(act)
            W = system.delassus(H)
            q = H @ v_free + (system.contact_offsets(act, rolling=True) if rolling
                              else system.contact_offsets(act))
            q[0::width] += act.e * np.minimum(uN[ia], 0.0)
            r0 = np.zeros((na, width))
            if prev_keys.size:
                order = np.argsort(prev_keys)
                pos = np.searchsorted(prev_keys, act.key, sorter=order)
                pos = np.minimum(pos, prev_keys.size - 1)
                hit = prev_keys[order[pos]] == act.key
                r0[hit] = prev_r[order[pos[hit]]]
            c2 = time.process_time()
            if rolling:
                def solver(**kw):
                    return solve_nsgs_rolling(W, q, act.mu, act.mu_r, tol=tol,
                                              max_sweeps=max_sweeps, check_every=check_every,
                                              **kw)
            else:
                def solver(**kw):
                    return solve_nsgs(W, q, act.mu, tol=tol, max_sweeps=max_sweeps,
                                      check_every=check_every, **kw)
            sol = solver(r0=r0.ravel())
            sweeps = sol.iterations
            if not sol.converged and np.any(r0):
                # a warm start can stall where the impulses are not unique (a hyperstatic
                # pile): measured 5000 sweeps stuck at 1.3e-6 where a cold start took 228
                cold = solver()
                sweeps += cold.iterations
                if cold.converged:
                    # (only then: in a deep pile the warm start carries the iterations of the
                    # steps before, and an unconverged cold answer would throw them away)
                    restarts += 1
                    sol = cold
            c3 = time.process_time()
            r = sol.r
            v1 = v_free + system.inv_mass * (H.T @ r)
            residual, converged = sol.residual, sol.converged
        else:
            c2 = c3 = time.process_time()
            r = np.zeros(0)
            v1 = v_free
            sweeps, residual, converged = 0, 0.0, True
        timing["broad_phase"] += c1 - c0
        timing["assembly"] += c2 - c1
        timing["solve"] += c3 - c2
        v1 = v1.reshape(N, 3)
        dq = h * (theta * v1 + (1.0 - theta) * v)
        x = x + dq[:, :2]
        phi = phi + dq[:, 2]
        v = v1
        t = float(t0) + (k + 1) * h
        rp = r.reshape(-1, width)
        prev_keys, prev_r = act.key, rp
        closed_keys = act.key[rp[:, 0] > 0.0] if na else np.zeros(0, dtype=np.int64)
        last = (act, r)
        on_wall = act.a < 0
        wall = -1 - act.a[on_wall]
        wall_imp = np.column_stack([np.bincount(wall, rp[on_wall, 0], minlength=nw),
                                    np.bincount(wall, rp[on_wall, 1], minlength=nw)])
        for key, val in (("t", t), ("candidates", cs.size), ("contacts", na), ("sweeps", sweeps),
                         ("residual", residual), ("converged", converged),
                         ("wall_impulse", wall_imp)):
            rec[key].append(val)
        stop = callback is not None and bool(callback(k, t, x, v))
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            status, message = -5, f"non-finite state after the step ending at t = {t!r}"
            break
        if (k + 1) % save_every == 0 or k + 1 == n_steps or stop:
            ts.append(t)
            xs.append(x.copy())
            phis.append(phi.copy())
            vs.append(v.copy())
        if not converged and on_unconverged == "stop":
            status = -3
            message = (f"NSGS did not converge at the step ending at t = {t!r}: residual "
                       f"{residual:.3e} > tol {tol:.1e} after {sweeps} sweeps; the run stopped")
            if ts[-1] != t:
                ts.append(t)
                xs.append(x.copy())
                phis.append(phi.copy())
                vs.append(v.copy())
            break
        if stop:
            break
    steps = {key: np.array(val, dtype=bool if key == "converged" else
                           float if key in ("t", "residual", "wall_impulse") else np.int64)
             for key, val in rec.items()}
    steps["wall_impulse"] = steps["wall_impulse"].reshape(steps["t"].size, nw, 2)
    bad = int(np.count_nonzero(~steps["converged"]))
    if status == 0:
        if bad:
            status = 1
            message = (f"{bad} of {steps['t'].size} steps ended with NSGS above tol {tol:.1e} "
                       f"(worst residual {np.max(steps['residual']):.3e}); their impulses "
                       f"were used")
        else:
            message = (f"{steps['t'].size} steps, every contact problem solved to tol {tol:.1e} "
                       f"(at most {int(np.max(steps['contacts'], initial=0))} contacts)")
    timing["cold_restarts"] = restarts
    return GranularResult(np.array(ts), np.array(xs), np.array(phis), np.array(vs), steps,
                          status, message, timing, last, tol)


def settle(system, x0, v0, h, *, max_steps=20_000, speed_tol=1e-3, min_steps=50, phi0=None,
           warm=None, **options):
    """Run :func:`simulate_disks` until every disk is slower than ``speed_tol`` (or ``max_steps``).

    Records the first and last states only. ``options`` go to
    :func:`simulate_disks` (``tol``, ``max_sweeps``, ``theta``, ...).

    Returns
    -------
    GranularResult
        Its last state is the settled one; ``steps`` holds every step.

    Examples
    --------
    >>> from moreau.model.granular import DiskSystem, HalfPlane
    >>> sys = DiskSystem([0.5], [1.0], walls=[HalfPlane((0, 0), (0, 1))])
    >>> res = settle(sys, [[0.0, 1.0]], [[0.0, 0.0, 0.0]], 0.01)
    >>> res.status, res.steps["t"].size < 20_000, round(float(res.x[-1, 0, 1]), 1)
    (0, True, 0.5)
    """
    speed_tol = positive("speed_tol", speed_tol)

    def at_rest(k, t, x, v):
        return k + 1 >= min_steps and float(np.max(np.abs(v[:, :2]), initial=0.0)) < speed_tol

    return simulate_disks(system, x0, v0, max_steps, h, phi0=phi0, save_every=max_steps,
                          callback=at_rest, warm=warm, **options)
