"""Unit conversions shared by the drive scenes (the paper's scaling)."""


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
