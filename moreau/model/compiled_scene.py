"""A scene written once: its Python methods evaluate its compiled model.

A scene that subclasses :class:`CompiledScene` defines only
``compiled_model()`` (:class:`moreau.compiled.CompiledModel`); ``mass``,
``forces``, ``force_jacobians``, ``gaps``, ``contact_jacobians`` and
``contact_drift`` call the model's ``numba.njit`` functions and unpack their
packed outputs into the arrays of the :class:`~moreau.model.scene.Scene`
interface. The Python and the compiled forms are then the same equations,
evaluated by the same code, and cannot drift apart.
"""

import numpy as np

from ..errors import MoreauError
from .scene import Scene

__all__ = ["CompiledScene"]


class _Unpacked:
    """The compiled model of one scene with the buffers its functions write into.

    The engine's contract (:mod:`moreau.compiled`): a function writes the same
    entries on every call, so each buffer is zero-filled once and reused.
    """

    __slots__ = ("model", "par", "n", "nc", "fr", "all_fr", "M", "D", "G", "Dr")

    def __init__(self, scene, model):
        if model is None:
            raise MoreauError(f"{type(scene).__name__} is a CompiledScene but its "
                              "compiled_model() returned None")
        if model.ndof != scene.ndof or model.ncontacts != scene.ncontacts:
            raise MoreauError(
                f"{type(scene).__name__}: its compiled model has ndof={model.ndof}, "
                f"ncontacts={model.ncontacts}; the scene has ndof={scene.ndof}, "
                f"ncontacts={scene.ncontacts}")
        n, nc = model.ndof, model.ncontacts
        self.model, self.par, self.n, self.nc = model, model.par, n, nc
        self.fr = scene.frictional_index
        self.all_fr = self.fr.size == nc
        self.M = None
        self.D = np.zeros((n, 1 + 2 * n))
        self.G = np.zeros((max(nc, 1), 3 + 2 * n))
        self.Dr = np.zeros((max(nc, 1), 2))
        if model.const_mass:
            self.M = np.zeros((n, n))
            model.mass(self.par, np.zeros(n), self.M)


def _vec(x):
    # the compiled functions are typed for contiguous float64 vectors
    return np.ascontiguousarray(x, dtype=np.float64)


class CompiledScene(Scene):
    """A scene whose Python methods evaluate its :meth:`compiled_model`.

    A subclass sets ``ndof``, ``mu`` and ``restitution`` as any scene does and
    defines ``compiled_model()``; it writes none of the six model methods.
    The compiled model is taken on the first call of one of them and kept
    (the scene's parameters are fixed at construction). Every method returns
    fresh arrays, the tangential rows only for the frictional contacts
    (``frictional_index``).

    Examples
    --------
    A ball of radius 0.1 above the floor, its model the one of
    :mod:`moreau.compiled`'s example (:func:`moreau.model.examples.drop_model`):

    >>> import numpy as np
    >>> from moreau.model.examples import drop_model
    >>> class Ball(CompiledScene):
    ...     ndof, mu, restitution = 1, np.zeros(1), np.array([0.5])
    ...     def compiled_model(self):
    ...         return drop_model(0.1)
    >>> ball = Ball()
    >>> ball.gaps([1.0], 0.0), ball.forces([1.0], [0.0], 0.0)
    (array([0.9]), array([-1.]))
    >>> WN, wN, WT, wT = ball.contact_jacobians([1.0], 0.0)
    >>> WN, WT.shape
    (array([[1.]]), (0, 1))
    """

    def _unpacked(self):
        u = self.__dict__.get("_compiled_unpacked")
        if u is None:
            u = _Unpacked(self, self.compiled_model())
            self.__dict__["_compiled_unpacked"] = u
        return u

    def __getstate__(self):
        # the buffers and dispatchers are rebuilt where the scene is unpickled
        state = dict(self.__dict__)
        state.pop("_compiled_unpacked", None)
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)

    # -- Scene interface: the compiled functions -------------------------------------
    def mass(self, q):
        u = self._unpacked()
        if u.M is not None:
            return u.M.copy()
        M = np.zeros((u.n, u.n))
        u.model.mass(u.par, _vec(q), M)
        return M

    def forces(self, q, v, t):
        u = self._unpacked()
        u.model.forces(u.par, _vec(q), _vec(v), float(t), u.D, False)
        return u.D[:, 0].copy()

    def force_jacobians(self, q, v, t):
        u = self._unpacked()
        n = u.n
        if not u.model.has_jacobians:
            # the model declares dh/dq and dh/dv identically zero
            return np.zeros((n, n)), np.zeros((n, n))
        u.model.forces(u.par, _vec(q), _vec(v), float(t), u.D, True)
        return u.D[:, 1:1 + n].copy(), u.D[:, 1 + n:].copy()

    def gaps(self, q, t):
        u = self._unpacked()
        if u.model.gaps is not None:
            u.model.gaps(u.par, _vec(q), float(t), u.G)
        else:
            u.model.contacts(u.par, _vec(q), float(t), u.G, True, False)
        return u.G[:u.nc, 0].copy()

    def contact_jacobians(self, q, t):
        u = self._unpacked()
        n, nc, G = u.n, u.nc, u.G
        u.model.contacts(u.par, _vec(q), float(t), G, False, u.fr.size > 0)
        if u.all_fr:
            WT, wT = G[:nc, 3 + n:].copy(), G[:nc, 2].copy()
        else:
            WT, wT = G[u.fr, 3 + n:], G[u.fr, 2]
        return G[:nc, 3:3 + n].copy(), G[:nc, 1].copy(), WT, wT

    def contact_drift(self, q, v, t):
        u = self._unpacked()
        Dr = u.Dr
        u.model.drift(u.par, _vec(q), _vec(v), float(t), Dr)
        wTbar = Dr[:u.nc, 1].copy() if u.all_fr else Dr[u.fr, 1]
        return Dr[:u.nc, 0].copy(), wTbar
