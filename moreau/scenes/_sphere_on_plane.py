"""A uniform sphere on a flat half-space in space, one frictional contact: the build shared
by :mod:`moreau.scenes.billiard_backspin` and :mod:`moreau.scenes.sphere_incline`."""

from ..model.space import SpaceModel, Sphere

__all__ = ["sphere_on_plane"]


def sphere_on_plane(name, p, gravity, spin, body, window):
    """The built scene of a uniform sphere (``J = (2/5) m r^2``) resting on the plane ``z = 0``.

    Parameters
    ----------
    name : str
        The scene's name.
    p : dataclass
        SI parameters with ``mass``, ``radius``, ``mu`` and ``speed``, the launch speed along
        ``x``; kept as the scene's ``params``.
    gravity : tuple of float
        Gravity in the plane's frame [m/s^2] (``z`` the plane's normal).
    spin : float
        Launch spin about ``y`` [rad/s].
    body : str
        The sphere's name.
    window : float
        The scene's default window [s].

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> p = SimpleNamespace(mass=2.0, radius=0.5, mu=0.3, speed=1.0)
    >>> sc = sphere_on_plane("ball", p, (0.0, 0.0, -9.81), 2.0, "ball", 1.0)
    >>> q0, v0 = sc.initial_state()
    >>> q0.tolist(), sc.params is p
    ([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0], True)
    """
    r = p.radius
    m = SpaceModel(gravity=gravity, length=r, mass=p.mass)
    plane = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    ball = m.add_body(p.mass, [0.4 * p.mass * r * r] * 3, position=(0.0, 0.0, r),
                      velocity=(p.speed, 0.0, 0.0), angular_velocity=(0.0, spin, 0.0), name=body)
    m.add_contact(ball, Sphere(r), plane, mu=p.mu)
    sc = m.build(name, default_window=window)
    sc.params = p
    return sc
