"""Agreement of two Moreau–Jean runs of the same scene (compiled and generic, warm and cold)."""

import numpy as np


def assert_forces_agree(a, b, h, vs, tol=1e-12):
    """The contact forces of two runs whose velocities agree to ``tol * vs``.

    A slipping or open contact's impulse is fixed by the state: its force
    agrees to ``tol`` of the force scale. A sticking contact's impulse is the
    velocity change it prevents, so its force carries the difference of the
    velocities divided by the step (two velocities, each within ``tol * vs``):
    at the box's stop, velocities 5e-14 apart after 640 steps of rounding
    give forces 1e-11 apart at h = 0.004. Where several contacts stick with
    equal tangential rows (the box resting on both corners) only the sum of
    their tangential forces is determined; each solver returns one vertex of
    the solution set, so the sum is compared.
    """
    fs = max(1.0, float(np.max(np.abs(a.force_N))))
    reg = np.atleast_2d(a.regime.T).T
    fN_a, fN_b = np.atleast_2d(a.force_N.T).T, np.atleast_2d(b.force_N.T).T
    fT_a, fT_b = np.atleast_2d(a.force_T.T).T, np.atleast_2d(b.force_T.T).T
    slip = np.atleast_2d(a.slip_velocity.T).T
    # a contact that ends the step at rest is held like a sticking one, whatever
    # its label (the box's stop at h = 0.004 ends a slipping step exactly at rest)
    stick = np.any((reg == 3) | ((reg != 0) & (np.abs(slip) <= 1e-9 * vs)), axis=1)
    free = ~stick
    np.testing.assert_allclose(fN_b[free], fN_a[free], rtol=0, atol=tol * fs)
    np.testing.assert_allclose(fT_b[free], fT_a[free], rtol=0, atol=tol * fs)
    atol = tol * fs + 2.0 * tol * vs / h
    np.testing.assert_allclose(fN_b[stick], fN_a[stick], rtol=0, atol=atol)
    several = np.sum(reg == 3, axis=1) >= 2
    one = stick & ~several
    np.testing.assert_allclose(fT_b[one], fT_a[one], rtol=0, atol=atol)
    np.testing.assert_allclose(fT_b[several].sum(axis=1), fT_a[several].sum(axis=1), rtol=0,
                               atol=atol)
