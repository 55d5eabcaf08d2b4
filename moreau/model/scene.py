"""The scene interface: what a mechanical system tells an integrator.

A scene works in its own dimensionless variables (time ``t``, coordinates
``q``, velocities ``v``). It declares only what it has: a frictionless contact
contributes no tangential row, a scene without contacts reports ``ncontacts == 0``.

Contact kinematics, for contact ``i``::

    g_i(q, t)                      gap, >= 0 admissible
    dg_i/dt   = WN[i] @ v + wN[i]  normal relative velocity
    gammaT_j  = WT[j] @ v + wT[j]  tangential relative (slip) velocity
    d2g_i/dt2 = WN[i] @ a + wNbar[i]
    dgammaT_j = WT[j] @ a + wTbar[j]

where ``j`` runs over the frictional contacts only (``mu > 0``), in the order
of ``frictional_index``. The contact reactions enter the equations of motion as::

    M(q) a = h(q, v, t) + WN.T @ lambdaN + WT.T @ lambdaT

so ``lambdaN >= 0`` pushes the gap open, and in positive slip
(``gammaT > 0``) Coulomb friction gives ``lambdaT = -mu * lambdaN``.

Joints (bilateral constraints), optional: a scene with ``n_joint_rows > 0``
states ``n_joint_rows`` rows ``gE(q, t) = 0`` with::

    dgE/dt   = WE @ v + wE        (joint_jacobians)
    d2gE/dt2 = WE @ a + wEbar     (joint_drift)

and their reactions add ``WE.T @ lambdaE`` (free in sign) to the equations of
motion. The default is none; a scheme that solves no joints refuses such a
scene by name (:func:`joint_row_count`).
"""

from dataclasses import fields, replace

import numpy as np

from ..errors import InputError, MoreauError
from .units import columns_of

__all__ = ["Scene", "params_with", "as_params", "FromParams", "fill_docstring", "joint_row_count", "velocity_count",
           "is_spatial"]

# central differences balance truncation (step^2) against rounding (eps / step)
_FD_STEP = float(np.finfo(float).eps) ** (1.0 / 3.0)


class Scene:
    """Base class of all scenes.

    Subclasses set ``ndof``, ``mu`` (array over contacts) and ``restitution``
    (array over contacts), and implement the methods below. Arrays are plain
    ``numpy`` float arrays in the scene's dimensionless units.
    """

    #: number of generalized coordinates
    ndof = 0
    #: friction coefficient of each contact, shape (ncontacts,)
    mu = np.zeros(0)
    #: Newton restitution coefficient of each contact, shape (ncontacts,)
    restitution = np.zeros(0)
    #: short name used in reports
    name = "scene"
    #: period of the drive in the scene's time, or None for a scene without a periodic drive
    period = None
    #: coordinates that do not enter the dynamics (e.g. the rotor position): a
    #: periodic steady state repeats everything else and advances these
    cyclic_coordinates = ()

    #: number of joint (bilateral, equality) rows; 0 for a scene without joints
    n_joint_rows = 0

    @property
    def ncontacts(self):
        return len(self.mu)

    @property
    def frictional_index(self):
        """Indices of the contacts with ``mu > 0`` (the only ones with tangential rows)."""
        return np.flatnonzero(np.asarray(self.mu) > 0.0)

    # -- dynamics ---------------------------------------------------------
    def mass(self, q):
        """Mass matrix ``M(q)``, shape (ndof, ndof), symmetric positive definite."""
        raise NotImplementedError

    def forces(self, q, v, t):
        """Generalized non-contact forces ``h(q, v, t)``, including gyroscopic terms."""
        raise NotImplementedError

    def force_jacobians(self, q, v, t):
        """``(dh/dq, dh/dv)``, each (ndof, ndof); used by implicit schemes.

        The default takes central differences of :meth:`forces` (``4 ndof``
        force evaluations, steps ``eps^(1/3) max(1, |x_j|)``), so that an
        implicit scheme is never silently explicit on a scene that does not
        give its Jacobians; a scene that knows them overrides this method.
        """
        q = np.asarray(q, dtype=float)
        v = np.asarray(v, dtype=float)
        n = q.size
        K = np.empty((n, n))
        C = np.empty((n, n))
        for j in range(n):
            dq = np.zeros(n)
            dq[j] = _FD_STEP * max(1.0, abs(q[j]))
            K[:, j] = (self.forces(q + dq, v, t) - self.forces(q - dq, v, t)) / (2.0 * dq[j])
            dv = np.zeros(n)
            dv[j] = _FD_STEP * max(1.0, abs(v[j]))
            C[:, j] = (self.forces(q, v + dv, t) - self.forces(q, v - dv, t)) / (2.0 * dv[j])
        return K, C

    # -- contacts ---------------------------------------------------------
    def gaps(self, q, t):
        """Gap of every contact, shape (ncontacts,)."""
        raise NotImplementedError

    def contact_jacobians(self, q, t):
        """Return ``(WN, wN, WT, wT)``.

        ``WN`` (ncontacts, ndof) and ``wN`` (ncontacts,) give the normal relative
        velocity; ``WT`` (nfrictional, ndof) and ``wT`` (nfrictional,) the slip
        velocity of the frictional contacts.
        """
        raise NotImplementedError

    def contact_drift(self, q, v, t):
        """Return ``(wNbar, wTbar)``, the velocity-dependent parts of the contact accelerations."""
        raise NotImplementedError

    # -- joints (optional) ---------------------------------------------------
    def joint_residuals(self, q, t):
        """``gE(q, t)``, the joints' position-level rows, shape (n_joint_rows,); 0 on the joints.

        The default: no joints (an empty array).
        """
        return np.zeros(0)

    def joint_jacobians(self, q, t):
        """``(WE, wE)``: ``dgE/dt = WE @ v + wE``, shapes (n_joint_rows, ndof) and (n_joint_rows,)."""
        return np.zeros((0, self.ndof)), np.zeros(0)

    def joint_drift(self, q, v, t):
        """``wEbar``: ``d2gE/dt2 = WE @ a + wEbar``, shape (n_joint_rows,)."""
        return np.zeros(0)

    def forcing_breakpoints(self, t0, t1):
        """Times in ``(t0, t1)`` where the prescribed motion or forcing is not smooth.

        A piecewise drive (a sawtooth's acceleration jumps) has them. An
        adaptive scheme ends its steps there: a step that spans a jump of the
        forcing can hide a whole stick–slip excursion between its samples.
        The default: none.

        Parameters
        ----------
        t0, t1 : float
            The open interval searched.

        Returns
        -------
        numpy.ndarray
            Sorted times, shape (k,).
        """
        return np.zeros(0)

    # -- the model's valid region -------------------------------------------
    #: the states the model is meant for, in words, or None where it holds everywhere
    #: (e.g. ``"0 < phi < pi"``); every scheme stops where a state leaves them
    valid_region = None
    #: a run of the scene's natural length in its own time, for a run that names none
    #: (the conformance suite); None: ten drive periods, or 1 without a drive
    default_window = None
    #: ``(scheme, {option: value})`` that ``moreau run`` takes where no scheme is named, or
    #: None: the event-driven reference where it takes the scene, else Moreau–Jean
    #: (:func:`moreau.analysis.history.default_scheme`)
    run_default = None

    def inside_valid_region(self, t, q, v):
        """Whether each state lies in the region where the model holds.

        Every scheme checks its recorded samples (each step end at the
        default ``save_every = 1``); the first one outside ends the run there
        with status ``-6``, naming :attr:`valid_region`, the time and the
        state. The
        contact law itself (``gap >= 0`` to the scheme's accuracy) is not
        part of the region: what lies outside it is a state the equations
        no longer describe (a rod turned past the floor, a ball through it).

        Parameters
        ----------
        t : ndarray, shape (k,)
        q, v : ndarray, shape (k, ndof)
            ``k`` states, one a row.

        Returns
        -------
        ndarray of bool, shape (k,)
            The default: all True.
        """
        return np.ones(np.shape(t), dtype=bool)

    def check_valid(self, q, v, t):
        """None inside the valid region; else a sentence naming the region left, the time and the state.

        Examples
        --------
        >>> from moreau.scenes import PainleveRod
        >>> rod = PainleveRod()
        >>> rod.check_valid([0.5, 0.1, 0.2], [0.0, 0.0, 0.0], 1.5) is None
        True
        >>> print(rod.check_valid([0.5, 0.1, -0.2], [0.0, 0.0, 0.0], 1.5))  # doctest: +ELLIPSIS
        the state left the model's valid region 0 < phi < pi ... at t = 1.5 (0.338643 s): q = [0.5, 0.1, -0.2], v = [0, 0, 0]
        """
        q = np.asarray(q, dtype=float).reshape(1, -1)
        v = np.asarray(v, dtype=float).reshape(1, -1)
        if self.valid_region is None or self.inside_valid_region(np.array([float(t)]), q, v)[0]:
            return None
        unit = self.time_unit_s
        si = f" ({float(t) * unit:.6g} s)" if unit else ""
        fmt = ", ".join
        return (f"the state left the model's valid region {self.valid_region} at t = {float(t):.6g}"
                f"{si}: q = [{fmt(f'{x:.6g}' for x in q[0])}], "
                f"v = [{fmt(f'{x:.6g}' for x in v[0])}]")

    def default_span(self):
        """The length of a run that names none, in the scene's time: :attr:`default_window`."""
        if self.default_window is not None:
            return float(self.default_window)
        return 10.0 * self.period if self.period is not None else 1.0

    # -- defaults and compiled form ---------------------------------------
    def initial_state(self):
        """A sensible default ``(q0, v0)``: the rest state or the scene's documented start."""
        raise NotImplementedError(f"{type(self).__name__} defines no initial_state()")

    def compiled_model(self):
        """The model in compiled form (:class:`moreau.compiled.CompiledModel`), or None.

        Scenes that return one run Moreau–Jean in the compiled loop of
        :mod:`moreau.integrators._mj_kernels`; the others take the generic path.
        """
        return None

    # -- units -------------------------------------------------------------
    #: seconds per unit of the scene's time; None for a scene without SI units (its
    #: time histories stay in its own units)
    time_unit_s = None

    def si_columns(self, result):
        """Time histories of ``result`` as ``[(name, unit, column)]``.

        Scenes with SI units give them in SI (``moreau.model.units``); this
        default gives the scene's own units, marked dimensionless (unit ``""``):
        ``t``, ``q_i``, ``v_i``, and per contact ``force_N``, ``force_T``
        (impulses over the step for time-stepping schemes), ``slip_velocity``,
        ``gap`` and ``regime``.
        """
        histories = {"t": result.t, "q": result.q, "v": result.v, "force_N": result.force_N,
                     "force_T": result.force_T, "slip_velocity": result.slip_velocity,
                     "gap": result.gap, "regime": result.regime}
        return columns_of(histories, dict.fromkeys(histories, ""))

    # -- drawing -------------------------------------------------------------
    def shapes(self, q, t=0.0):
        """Primitive shapes of the scene at SI coordinates ``q`` and time ``t`` [s].

        Each scene that can be drawn (``moreau animate``) overrides this; the
        shapes and their units are those of :mod:`moreau.model.drawing`.
        This default refuses, naming the scene.
        """
        raise MoreauError(f"scene {self.name!r} ({type(self).__name__}) cannot be drawn: it "
                          "defines no shapes(q, t)")

    # -- conveniences shared by all scenes --------------------------------
    def contact_velocities(self, q, v, t):
        """Normal and tangential relative velocities ``(gN_dot, gammaT)``."""
        WN, wN, WT, wT = self.contact_jacobians(q, t)
        return WN @ v + wN, WT @ v + wT

    def delassus(self, q, t):
        """Delassus blocks ``W M^-1 W^T`` over the stacked rows ``[WN; WT]``."""
        WN, _, WT, _ = self.contact_jacobians(q, t)
        W = np.vstack([WN, WT])
        return W @ np.linalg.solve(self.mass(q), W.T)


def joint_row_count(scene):
    """The number of joint rows of ``scene`` (0 for a scene, or a duck-typed one, without joints).

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> joint_row_count(BouncingBall())
    0
    """
    return int(getattr(scene, "n_joint_rows", 0) or 0)


def velocity_count(scene):
    """The number of velocities of ``scene``: ``nvel`` of a spatial one, else ``ndof``.

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> velocity_count(BouncingBall())
    1
    """
    return int(getattr(scene, "nvel", None) or scene.ndof)


def is_spatial(scene):
    """Whether ``scene`` is a spatial one (its orientations are quaternions, its friction a cone).

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> is_spatial(BouncingBall())
    False
    """
    return bool(getattr(scene, "spatial", False))


def params_with(cls, params, overrides):
    """``params`` (or the defaults) with keyword overrides, unknown keys rejected."""
    if params is None:
        params = cls()
    elif not isinstance(params, cls):
        raise InputError(f"`params` must be a {cls.__name__}, got {type(params).__name__}")
    known = {f.name for f in fields(cls)}
    for key in overrides:
        if key not in known:
            raise InputError(f"`{key}` is not a parameter of {cls.__name__}; "
                             f"known parameters: {sorted(known)}")
    return replace(params, **overrides)


def as_params(cls, params):
    """``params`` as a ``cls``: itself if it is one, else ``cls(**params)`` from a mapping."""
    return params if isinstance(params, cls) else cls(**params)


def fill_docstring(cls, line, entries):
    """Replace the line ``line`` of ``cls``'s own docstring by ``entries``, one a line at its indent.

    So that a docstring section every class of a family shares is written once.

    Examples
    --------
    >>> class A:
    ...     '''Doc.
    ...
    ...     {two}
    ...     '''
    >>> fill_docstring(A, "{two}", ("first", "second"))
    >>> A.__doc__.splitlines()[2:4]
    ['    first', '    second']
    """
    doc = cls.__dict__.get("__doc__")
    if doc and line in doc:
        head, _, tail = doc.partition(line)
        indent = head[head.rfind("\n") + 1:]
        cls.__doc__ = head + ("\n" + indent).join(entries) + tail


class FromParams:
    """A scene made from one frozen dataclass of SI parameters, its class attribute ``Params``.

    ``SceneClass(params=None, **overrides)`` takes ``params`` (a ``Params``;
    the defaults if omitted) with the overrides applied by :func:`params_with`,
    keeps it as ``self.params`` and hands it to the scene's ``_setup(p)``,
    which sets the scene's own quantities. The line ``{params}`` in a
    subclass's docstring is replaced by its Parameters section, the entries
    of these two arguments, so that each scene does not write them again.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class DropParams:
    ...     height: float = 1.0
    >>> class Drop(FromParams):
    ...     '''A point dropped from ``height``.
    ...
    ...     {params}
    ...     '''
    ...     Params = DropParams
    ...     def _setup(self, p):
    ...         self.q0 = p.height
    >>> Drop(height=2.0).q0
    2.0
    >>> Drop.__doc__.splitlines()[4].strip()
    'params : DropParams, optional'
    """

    #: the scene's parameter dataclass
    Params = None

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.Params is not None:
            fill_docstring(cls, "{params}", (
                "Parameters", "----------", f"params : {cls.Params.__name__}, optional",
                "    SI parameters; the defaults if omitted.", "**overrides",
                "    Individual parameters replacing those of ``params``, by name."))

    def __init__(self, params=None, **overrides):
        self.params = params_with(self.Params, params, overrides)
        self._setup(self.params)
