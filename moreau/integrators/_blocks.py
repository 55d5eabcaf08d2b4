"""Recording for schemes that run blocks of steps in a compiled loop.

A compiled loop writes its samples into buffers, one block per call; a step
taken in Python inside such a run (a contact problem handed back to the
generic step) is a one-sample block. :class:`CompiledRecording` keeps the
blocks and assembles them into a :class:`SimulationResult`; a scheme sets
``self._fast`` (and ``self._blocks = []``) when it runs compiled.
"""

import numpy as np

from .result import STATUS_MESSAGES, SimulationResult

__all__ = ["CompiledRecording"]


class CompiledRecording:
    """Mixin of :class:`~moreau.integrators.base.Integrator` subclasses with a compiled path."""

    _fast = False

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

    def result(self):
        """Assemble the recorded samples into a :class:`SimulationResult`."""
        if not self._fast:
            return super().result()
        n, nc = self.scene.ndof, self.scene.ncontacts
        if self._blocks:
            t, q, v, reg, fN, fT, slip, gap = (np.concatenate(c) for c in zip(*self._blocks))
        else:
            t = np.zeros(0)
            q = v = np.zeros((0, n))
            reg = np.zeros((0, nc), dtype=np.int64)
            fN = fT = slip = gap = np.zeros((0, nc))
        code = self.status_code
        return SimulationResult(
            t=t, q=q, v=v, regime=reg.astype(int), force_N=fN, force_T=fT,
            slip_velocity=slip, gap=gap, events=[], status=code,
            message=self.message or STATUS_MESSAGES.get(code, ""), scheme=self.scheme,
            stats=dict(self.counters))
