"""The granular column's runout against its aspect ratio, each column as wide as its size needs.

The normalised runout ``(L_inf - L0) / L0`` of a collapsing column depends
on its aspect ratio ``a = H0 / L0`` alone in the experiments. In
two-dimensional (channel) geometry:

* E. Lajeunesse, J. B. Monnier and G. M. Homsy, *Granular slumping on a
  horizontal surface*, Phys. Fluids 17 (2005) 103302: linear in ``a`` for
  ``a`` below about 3, ``a^(2/3)`` beyond;
* G. Lube, H. E. Huppert, R. S. J. Sparks and A. Freundt, *Collapses of
  two-dimensional granular columns*, Phys. Rev. E 72 (2005) 041301: the
  same two branches, ``a`` and ``a^(2/3)``;
* L. Staron and E. J. Hinch, J. Fluid Mech. 545 (2005) 1-27, with
  two-dimensional discrete grains (rigid disks, contact dynamics as here):
  the same exponents.

Only the exponent of the large-``a`` branch is compared here (2/3); the
prefactors depend on the material and are not.

:func:`runout_rows` collapses one column per ``(a, L0)`` pair
(:func:`moreau.scenes.granular_column.collapse`, the broad phase every
step), so that a short column can be wide and a tall one narrow at a
similar number of grains; :func:`moreau.scenes.granular_column.fit_runout`
fits both branches. ``benchmarks/granular_runout.py`` runs it a row at a
time, writing each as it finishes.

Measured (the defaults above, ``mu = mu_floor = mu_wall = 0.5``, ``e = 0``,
``h = 0.01``, ``tol = 1e-5``, 500 sweeps, seed 0; every front stopped
before ``max_time``; 27 to 133 s of CPU a column; 24-48 % of the steps
ended above ``tol``, worst residual 1e-2):

=========  ========  =====  =====================  ===============================
``a`` aim  ``L0/d``  disks  ``a = H0 / L0``        runout ``(L_inf - L0) / L0``
=========  ========  =====  =====================  ===============================
0.5        10        72     0.63                   0.13
1          8         93     1.25                   0.43
2          6         104    2.53                   1.65
4          5         145    4.73                   3.08
8          4         185    9.64                   5.28
=========  ========  =====  =====================  ===============================

The large branch (``a > 3``, two points) fits ``0.95 a^0.76`` against the
published ``a^(2/3)`` (with ``a = 2.53`` in it, three points: ``0.76
a^0.87``); the log-log slopes between neighbours fall from 1.72 and 1.92
(``a`` below 2.5) to 1.00 and 0.76. The small branch is not linear: its
slope is 1.8 (least squares through the origin ``lambda = 0.57`` up to ``a
= 3``), where the experiments' runout is proportional to ``a``: with
rolling resistance ``0.1 d`` a short column of rigid disks barely spreads
(0.13 at ``a = 0.63``). The columns aimed at ``a`` settle taller than
aimed at narrow ``L0`` (the packing estimate of
:func:`~moreau.scenes.granular_column.column_system`); the measured ``a``
is used. One seed a column: the scatter between fillings is not measured.
"""

from ...errors import InputError
from ...scenes.granular_column import collapse, fit_runout

__all__ = ["runout_rows"]

#: the study's defaults: ``+-20 %`` radii, rolling resistance a tenth of a diameter,
#: random horizontal start speeds (columns of rolling-resistant disks stand in the start
#: lattice's stacks otherwise: :mod:`moreau.scenes.granular_column`)
DEFAULTS = {"spread": 2.0 / 3.0, "mu_r": 0.1 * 0.005, "diameter": 0.005, "scatter": 0.5,
            "max_time": 80.0, "settle_time": 30.0}


def runout_rows(cases, *, a_split=3.0, on_row=None, **options):
    """Collapse one column per ``(aspect, L0)`` (``L0`` in diameters); the rows and their fit.

    ``options`` go to :func:`~moreau.scenes.granular_column.collapse` over
    the study's defaults (``spread = 2/3``, ``mu_r = 0.1 d``, ``scatter =
    0.5``, ``max_time = 80``, ``settle_time = 30``). ``on_row(row)`` is
    called as each column finishes. ``a_split`` divides the two branches
    (the measured aspect ratios; Lajeunesse et al.: about 3).

    Returns
    -------
    rows : list of dict
        :func:`~moreau.scenes.granular_column.collapse`'s, each with ``aim``.
    fit : dict
        :func:`~moreau.scenes.granular_column.fit_runout` of the rows.

    Examples
    --------
    >>> rows, fit = runout_rows([(0.5, 3.0)], max_time=0.3, settle_time=0.2)
    >>> len(rows), rows[0]["L0"], fit["p"] is None
    (1, 3.0, True)
    """
    cases = [(float(a), float(L0)) for a, L0 in cases]
    if not cases:
        raise InputError("`cases` must hold one (aspect, L0) pair at least")
    opts = {**DEFAULTS, **options}
    d = opts["diameter"]
    rows = []
    for a, L0 in cases:
        row = collapse(aspect=a, width=L0 * d, **opts)
        row["aim"] = a
        rows.append(row)
        if on_row is not None:
            on_row(row)
    fit = fit_runout([r["aspect"] for r in rows], [r["runout"] for r in rows], a_split)
    return rows, fit
