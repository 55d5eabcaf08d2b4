"""The compiled path of a time-stepping scheme: its choice, its blocks, its recording.

A compiled loop (a template of :mod:`moreau.integrators._loops`) runs up to
:data:`FAST_BLOCK` steps a call and writes its samples into buffers, one
block per call; a step taken in Python inside such a run (a contact problem
handed back to the generic step) is a one-sample block.
:class:`CompiledRecording` decides whether a run is compiled
(:meth:`~CompiledRecording._choose_compiled`), runs one block and keeps its
books (:meth:`~CompiledRecording._run_block`), and assembles the blocks into
a :class:`SimulationResult`.
"""

import copy

import numpy as np

from ..errors import InputError, MoreauError
from ..model.scene import velocity_count
from ._loops import runner_for
from ._mj_kernels import (LCP_HANDBACK, NUMERICAL, PAINLEVE, SINGULAR, STAT_NAMES,
                          new_lcp_control, new_stats)
from ._dense import join_to_last
from .result import STATUS_MESSAGES, SimulationResult

__all__ = ["CompiledRecording", "FAST_BLOCK", "EXPLICIT_BLOWUP", "states_since", "keep_rows", "result_of_rows"]

# time steps per call of the compiled loop: large enough to hide the call,
# small enough for a live progress bar and a prompt Ctrl-C
FAST_BLOCK = 1 << 16

#: the failure message of an explicit scheme whose state overflowed (``{t}``, ``{h}``)
EXPLICIT_BLOWUP = ("non-finite state after the step at t = {t!r} (the explicit step `h` = {h!r} "
                   "is probably too large for the stiffest force)")


class CompiledRecording:
    """Mixin of :class:`~moreau.integrators.base.Integrator` subclasses with a compiled path."""

    _fast = False

    def _choose_compiled(self, fast, model, lcp_method, lemke_max_iter=None, warm_start=False):
        """Check ``fast`` and set up the compiled path where it applies.

        ``model`` is the scene's compiled model or None. A forced QP solver is
        a request to run that solver, so it takes the generic path.
        """
        if fast not in ("auto", True, False):
            raise InputError(f"`fast` must be 'auto', True or False, got {fast!r}")
        if fast is True and model is None:
            raise InputError(f"`fast=True` needs a scene with a compiled model "
                             f"(`compiled_model()`); {type(self.scene).__name__} has none, or a "
                             f"subclass changed its equations; use fast='auto' or False")
        if fast is True and lcp_method == "qp":
            raise InputError("`fast=True` solves contacts in closed form or by Lemke; "
                             "`lcp_method='qp'` needs fast='auto' or False")
        self._fast = model is not None and fast is not False and lcp_method != "qp"
        if self._fast:
            self._model = model
            self._stats = new_stats()
            # options of the loop's contact problems and the warm start's memory,
            # carried from one compiled block to the next
            self._lcp_ctl = new_lcp_control(self.scene.ncontacts,
                                            force_lemke=lcp_method == "lemke",
                                            warm_start=warm_start, max_iter=lemke_max_iter or 0)
            self._blocks = []
            for name in STAT_NAMES:
                self.counters.setdefault(name, 0)

    def _run_block(self, template, before, after):
        """Run one block of ``template``'s loop and keep the books; return its status.

        The loop's arguments are ``par, mu, e, t0, h, t_bound, k0, nmax``,
        then ``before``, ``self.save_every, record_initial``, ``after``, the
        recording buffers and the statistics. The caller passes copies of its
        state in ``before``/``after``, stores them back after the call, then
        hands the status to :meth:`_after_block`.
        """
        buf = self._block_buffers(velocity_count(self.scene))
        st = self._stats
        st[:] = 0.0
        m = self._model
        status, k, nrec = self._runner(template)(
            m.par, self.mu_c, self.e_c, self.t0, self.h, self.t_bound, self._k,
            getattr(self, "_block_limit", FAST_BLOCK),
            *before, self.save_every, self._pending_initial, *after, *buf, st)
        self._keep_block(k, nrec, buf)
        c = self.counters
        for name, x in zip(STAT_NAMES, st):
            c[name] = max(c[name], float(x)) if name.startswith("max_") else c[name] + int(x)
        return status

    def _block_buffers(self, nv):
        """A block's recording buffers: times, ``q``, ``v`` (``nv`` columns), the
        regimes, normal and tangential forces, slips and gaps of the contacts."""
        n, nc = self.scene.ndof, self.scene.ncontacts
        ns = FAST_BLOCK // self.save_every + 2
        return (np.empty(ns), np.empty((ns, n)), np.empty((ns, nv)),
                np.empty((ns, nc), dtype=np.int64), np.empty((ns, nc)), np.empty((ns, nc)),
                np.empty((ns, nc)), np.empty((ns, nc)))

    def _keep_block(self, k, nrec, buf):
        """The books after a block that reached step ``k`` and recorded ``nrec`` rows of ``buf``."""
        ndone = k - self._k
        if nrec:
            self._blocks.append(tuple(b[:nrec].copy() for b in buf))
        if ndone:
            self._pending_initial = False
        self._k = k
        t = self.t0 + k * self.h
        self.t = self.t_bound if t >= self.t_bound - 1e-9 * self.h else t
        self.counters["steps"] += ndone - 1     # the base class counts one step per call of _step_impl

    def _runner(self, template):
        """The compiled loop of ``template`` on the run's model (:func:`runner_for`)."""
        return runner_for(self._model, template, self.scene)

    def _after_block(self, status, handback=(LCP_HANDBACK, PAINLEVE),
                     singular="the mass matrix is singular at t = {t!r}",
                     numerical="non-finite state after the step at t = {t!r}"):
        """Act on a block's status once the caller has stored its state back.

        A status in ``handback`` has the generic step take the step the loop
        stopped at (QP fallback, or the full diagnosis of a Painlevé case);
        ``singular`` and ``numerical`` are the failure messages (``{t}``: the
        time reached, ``{h}``: the step).
        """
        if status in handback:
            if self._stop_if_diverged():
                # a blown-up state handed back: its Python step would overflow on the way
                return
            self.counters["steps"] += 1
            self._generic_step()
        elif status == SINGULAR:
            self._fail(-5, singular.format(t=self.t, h=self.h))
        elif status == NUMERICAL:
            self._fail(-5, numerical.format(t=self.t, h=self.h))

    def _record(self, t, q, v, regime, force_N, force_T, slip, gap):
        if not self._fast:
            return super()._record(t, q, v, regime, force_N, force_T, slip, gap)
        # a step taken in Python inside a compiled run: a one-sample block
        nc = self.scene.ncontacts
        self._blocks.append((np.array([t], float), np.array(q, float).reshape(1, -1),
                             np.array(v, float).reshape(1, -1),
                             np.asarray(regime, np.int64).reshape(1, nc),
                             *(np.asarray(a, float).reshape(1, nc)
                               for a in (force_N, force_T, slip, gap))))

    #: what a snapshot leaves out: the scene and the compiled model are shared, the
    #: recorded blocks are cut back by count
    _NOT_SNAPSHOT = ("scene", "_model", "_blocks", "_samples", "_pieces")

    def _snapshot(self):
        if not self._fast:
            return None
        state = {k: copy.deepcopy(v) for k, v in vars(self).items() if k not in self._NOT_SNAPSHOT}
        return state, len(self._blocks)

    def _loop_steps_to(self, start, t, rows):
        """Steps of the compiled loop from the state ``start`` (a snapshot) to the sample at ``t``.

        A fixed-step loop: from the grid ``t0 + k h``; the run's last step ends
        on ``t_bound`` (the loop stops there by itself).
        """
        if t >= self.t_bound:
            return FAST_BLOCK
        return int(round((t - self.t0) / self.h)) - start["_k"]

    def _replay(self, snapshot, t, rows):
        if snapshot is None:
            return False
        state, nblocks = snapshot
        limit = self._loop_steps_to(state, t, rows)
        if not 0 < limit <= FAST_BLOCK:
            return False
        del self._blocks[nblocks:]
        vars(self).update(copy.deepcopy(state))
        self._block_limit = limit
        try:
            self._step_impl()
        except MoreauError:
            pass        # it stopped before where the first call failed; the cut decides
        finally:
            del self._block_limit
        self.counters["steps"] += 1      # as Integrator.step counts a call
        return True

    def _unchecked_states(self):
        if not self._fast:
            return super()._unchecked_states()
        return states_since(self._blocks, self._region_seen)

    def _keep_checked(self, count):
        if not self._fast:
            return super()._keep_checked(count)
        self._blocks = keep_rows(self._blocks, self._region_seen, count)
        self._region_seen = len(self._blocks)

    def _rows_since(self):
        if not self._fast:
            return super()._rows_since()
        new = self._blocks[self._seen:]
        self._seen = len(self._blocks)
        if not new:
            return None
        rows = tuple(np.concatenate(c) for c in zip(*new))
        rows = rows[:3] + (rows[3].astype(int),) + rows[4:]
        return join_to_last(self, rows)

    def result(self):
        """Assemble the recorded samples into a :class:`SimulationResult`."""
        if not self._fast:
            return super().result()
        return result_of_rows(self, self._blocks)


def result_of_rows(integrator, blocks):
    """The :class:`SimulationResult` of ``integrator`` from its row blocks
    ``(t, q, v, regime, force_N, force_T, slip, gap)``."""
    n, nc = integrator.scene.ndof, integrator.scene.ncontacts
    if blocks:
        t, q, v, reg, fN, fT, slip, gap = (np.concatenate(c) for c in zip(*blocks))
    else:
        t = np.zeros(0)
        q = np.zeros((0, n))
        v = np.zeros((0, velocity_count(integrator.scene)))
        reg = np.zeros((0, nc), dtype=np.int64)
        fN = fT = slip = gap = np.zeros((0, nc))
    code = integrator.status_code
    return SimulationResult(
        t=t, q=q, v=v, regime=reg.astype(int), force_N=fN, force_T=fT,
        slip_velocity=slip, gap=gap, events=[], status=code,
        message=integrator.message or STATUS_MESSAGES.get(code, ""), scheme=integrator.scheme,
        stats=dict(integrator.counters))


def states_since(blocks, seen):
    """``(t, q, v)`` of the row blocks ``blocks[seen:]`` (each ``(t, q, v, ...)``), or None."""
    new = blocks[seen:]
    if not new:
        return None
    return tuple(np.concatenate([b[i] for b in new]) for i in range(3))


def keep_rows(blocks, seen, count):
    """``blocks`` with only ``count`` rows after ``blocks[:seen]`` (all of them for None)."""
    if count is None:
        return blocks
    kept = blocks[:seen]
    for b in blocks[seen:]:
        if count <= 0:
            break
        kept.append(tuple(x[:count] for x in b))
        count -= len(b[0])
    return kept
