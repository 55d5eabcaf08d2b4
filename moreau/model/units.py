"""Unit conversions shared by the scenes: the paper's drive scaling and the validation scenes' SI scales."""

import math
from collections import namedtuple

import numpy as np

#: quantities converted to SI by ``to_si``; ``None`` where not requested
SIValues = namedtuple("SIValues", ["t", "q", "v", "force"])

#: keys every scene's ``to_si(result)`` returns, for ``n`` samples, ``ndof``
#: coordinates and ``nc`` contacts: ``t`` (n,) [s]; ``q`` (n, ndof) [m, or rad for
#: an angle]; ``v`` (n, ndof) [m/s or rad/s]; ``force_N``, ``force_T`` (n, nc) [N]
#: (time-stepping schemes: impulse over the step divided by the step);
#: ``slip_velocity`` (n, nc) [m/s]; ``gap`` (n, nc) [m]; ``regime`` (n, nc) codes of
#: :class:`moreau.regimes.Regime`. A scene may add named extras (the drives'
#: ``x2``, ``v2``, ``phi``).
COMMON_KEYS = ("t", "q", "v", "force_N", "force_T", "slip_velocity", "gap", "regime")

#: SI unit of each named time history that a scene's ``to_si`` returns (``q`` and
#: ``v`` take theirs per coordinate, see :func:`si_histories`)
SI_UNITS = {"t": "s", "x2": "m", "v2": "m/s", "phi": "rad", "phi_a": "rad", "phi_b": "rad",
            "force_N": "N", "force_T": "N", "slip_velocity": "m/s", "gap": "m", "regime": ""}


def si_histories(result, time, length, force, angles=()):
    """The :data:`COMMON_KEYS` of ``result`` in SI units.

    Parameters
    ----------
    result : SimulationResult
    time, length, force : float
        SI size of the scene's units of time [s], length [m] and force [N].
    angles : sequence of int
        Coordinates that are angles (kept in rad; their rates in rad/s).

    Returns
    -------
    dict
        See :data:`COMMON_KEYS`.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> r = SimpleNamespace(t=np.array([1.0]), q=np.array([[0.5, 2.0]]),
    ...                     v=np.array([[1.0, 1.0]]), force_N=np.array([[3.0]]),
    ...                     force_T=np.array([[0.0]]), slip_velocity=np.array([[1.0]]),
    ...                     gap=np.array([[0.0]]), regime=np.array([[0]]))
    >>> si = si_histories(r, time=0.5, length=0.01, force=2.0, angles=(0,))
    >>> si["q"].tolist(), si["v"].tolist(), si["force_N"].tolist()
    ([[0.5, 0.02]], [[2.0, 0.02]], [[6.0]])
    """
    ndof = result.q.shape[1]
    qs = np.array([1.0 if i in angles else length for i in range(ndof)])
    return {"t": result.t * time, "q": result.q * qs, "v": result.v * (qs / time),
            "force_N": result.force_N * force, "force_T": result.force_T * force,
            "slip_velocity": result.slip_velocity * (length / time), "gap": result.gap * length,
            "regime": result.regime.copy()}


def columns_of(histories, units):
    """``[(name, unit, 1-D array)]`` of a ``to_si`` dict: one column per contact of 2-D entries.

    ``units`` maps each name to its unit, or to one unit per column of a 2-D entry.
    """
    out = []
    for name, arr in histories.items():
        arr = np.asarray(arr)
        unit = units[name]
        if arr.ndim == 1:
            out.append((name, unit, arr))
            continue
        for j in range(arr.shape[1]):
            out.append((f"{name}_{j}", unit[j] if isinstance(unit, (list, tuple)) else unit,
                        arr[:, j]))
    return out


def common_columns(histories, angles=()):
    """``[(name, unit, 1-D array)]`` of the :data:`COMMON_KEYS` of a ``to_si`` dict.

    One column per coordinate (``q_0``, ``v_0``, ...) and per contact
    (``force_N_0``, ...); the extras a scene adds are left out, so that every
    scene's table has the same columns.
    """
    ndof = np.asarray(histories["q"]).shape[1]
    units = dict(SI_UNITS, q=["rad" if i in angles else "m" for i in range(ndof)],
                 v=["rad/s" if i in angles else "m/s" for i in range(ndof)])
    return columns_of({k: histories[k] for k in COMMON_KEYS}, units)


class DriveUnits:
    """SI conversions for a scene scaled by a rod length ``l`` and a drive frequency ``w``.

    Lengths are over ``l = params.length``, time is ``tau = w t`` with
    ``w = omega``, and forces are over ``force_scale = m l w^2``; the scene sets
    these three attributes.
    """

    def displacement_to_si(self, du2):
        """Dimensionless rotor displacement to metres."""
        return du2 * self.params.length

    def velocity_to_si(self, dv2):
        """Dimensionless rotor velocity (d/dtau) to metres per second."""
        return dv2 * self.params.length * self.omega

    def force_to_si(self, f):
        """Dimensionless force to newtons."""
        return f * self.force_scale

    @property
    def time_unit_s(self):
        """Seconds per unit of the scene's time ``tau = w t``."""
        return 1.0 / self.omega

    #: coordinates that are angles (rad, not scaled by the rod length)
    angle_coordinates = ()

    def _si_histories(self, result):
        return si_histories(result, 1.0 / self.omega, self.params.length, self.force_scale,
                            self.angle_coordinates)

    def si_columns(self, result):
        """The common SI time histories of ``result`` as ``[(name, unit, column)]`` (see :meth:`to_si`)."""
        return common_columns(self.to_si(result), self.angle_coordinates)


class SIUnits:
    """SI conversion shared by the validation scenes of this package.

    A scene using it sets ``time`` [s], ``force`` [N] and ``length`` [m] (the
    SI size of one dimensionless unit) and may override ``_qscale`` when some
    coordinates are angles.
    """

    #: coordinates that are angles (their SI unit is rad, not m)
    angle_coordinates = ()

    def _scale_by_weight(self, length, mass, gravity):
        # a scene under gravity: lengths over L, time over sqrt(L / g), forces over the weight m g
        self.length = length
        self.time = math.sqrt(length / gravity)
        self.force = mass * gravity

    def _qscale(self):
        # one scale for all coordinates, so that scalars convert to scalars
        return self.length

    @property
    def time_unit_s(self):
        """Seconds per unit of the scene's time."""
        return self.time

    def si_columns(self, result):
        """The SI time histories of ``result`` as ``[(name, unit, column)]`` (see :meth:`to_si`)."""
        return common_columns(self.to_si(result), self.angle_coordinates)

    def displacement_to_si(self, dq):
        """A dimensionless displacement to metres."""
        return dq * self.length

    def velocity_to_si(self, dv):
        """A dimensionless velocity to metres per second."""
        return dv * self.length / self.time

    def force_to_si(self, f):
        """A dimensionless force to newtons."""
        return f * self.force

    def to_si(self, result=None, *, t=None, q=None, v=None, force=None):
        """Convert to SI units.

        Parameters
        ----------
        result : SimulationResult, optional
            A run of this scene. If given, a dict of SI time histories is
            returned with the :data:`COMMON_KEYS`: ``t`` [s], ``q``, ``v``
            (lengths in m, angles in rad), ``force_N``, ``force_T`` [N],
            ``slip_velocity`` [m/s], ``gap`` [m] and the ``regime`` codes.
        t, q, v, force : array_like, optional
            Dimensionless time, coordinates, velocities and contact forces,
            converted individually when ``result`` is not given.

        Returns
        -------
        dict or SIValues
        """
        T, F = self.time, self.force
        if result is not None:
            return si_histories(result, T, self.length, F, self.angle_coordinates)
        qs = self._qscale()
        return SIValues(None if t is None else np.asarray(t, float) * T,
                        None if q is None else np.asarray(q, float) * qs,
                        None if v is None else np.asarray(v, float) * qs / T,
                        None if force is None else np.asarray(force, float) * F)

    def from_si(self, *, t=None, q=None, v=None, force=None):
        """Inverse of :meth:`to_si` for individual quantities (SI -> dimensionless)."""
        T, F = self.time, self.force
        qs = self._qscale()
        return SIValues(None if t is None else np.asarray(t, float) / T,
                        None if q is None else np.asarray(q, float) / qs,
                        None if v is None else np.asarray(v, float) * T / qs,
                        None if force is None else np.asarray(force, float) / F)
