"""Unit conversions shared by the scenes: the paper's drive scaling and the validation scenes' SI scales."""

from collections import namedtuple

import numpy as np

#: quantities converted to SI by ``to_si``; ``None`` where not requested
SIValues = namedtuple("SIValues", ["t", "q", "v", "force"])

#: SI unit of each named time history that a scene's ``to_si`` returns
SI_UNITS = {"t": "s", "x2": "m", "v2": "m/s", "phi": "rad", "phi_a": "rad", "phi_b": "rad",
            "normal_force": "N", "tangential_force": "N", "force_N": "N", "force_T": "N",
            "slip_velocity": "m/s", "gap": "m", "regime": ""}


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

    def si_columns(self, result):
        """The SI time histories of ``result`` as ``[(name, unit, column)]`` (see :meth:`to_si`)."""
        return columns_of(self.to_si(result), SI_UNITS)


class SIUnits:
    """SI conversion shared by the validation scenes of this package.

    A scene using it sets ``time`` [s], ``force`` [N] and ``length`` [m] (the
    SI size of one dimensionless unit) and may override ``_qscale`` when some
    coordinates are angles.
    """

    #: coordinates that are angles (their SI unit is rad, not m)
    angle_coordinates = ()

    def _qscale(self):
        # one scale for all coordinates, so that scalars convert to scalars
        return self.length

    @property
    def time_unit_s(self):
        """Seconds per unit of the scene's time."""
        return self.time

    def si_columns(self, result):
        """The SI time histories of ``result`` as ``[(name, unit, column)]`` (see :meth:`to_si`)."""
        n = result.q.shape[1]
        ang = set(self.angle_coordinates)
        units = dict(SI_UNITS, q=["rad" if i in ang else "m" for i in range(n)],
                     v=["rad/s" if i in ang else "m/s" for i in range(n)])
        return columns_of(self.to_si(result), units)

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
            returned: ``t`` [s], ``q``, ``v`` (lengths in m, angles in rad),
            ``force_N``, ``force_T`` [N], ``slip_velocity`` [m/s], ``gap`` [m]
            and the ``regime`` codes.
        t, q, v, force : array_like, optional
            Dimensionless time, coordinates, velocities and contact forces,
            converted individually when ``result`` is not given.

        Returns
        -------
        dict or SIValues
        """
        T, F, L = self.time, self.force, self.length
        qs = self._qscale()
        if result is not None:
            return {"t": result.t * T, "q": result.q * qs, "v": result.v * qs / T,
                    "force_N": result.force_N * F, "force_T": result.force_T * F,
                    "slip_velocity": result.slip_velocity * (L / T), "gap": result.gap * L,
                    "regime": result.regime.copy()}
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
