"""CompiledScene: the Python methods unpack the compiled model's outputs, by the interface's rules.

A toy with one frictionless and one frictional contact, a mass matrix that
depends on q and forces with Jacobians, so that every branch of the
unpacking is reached: the values are written here by hand from the model.
"""

import math
import pickle

import numpy as np
import pytest
from numba import njit

from moreau.compiled import CompiledModel
from moreau.errors import MoreauError
from moreau.model.compiled_scene import CompiledScene

K_SPRING, C_DAMP, WALL_SPEED = 3.0, 0.5, 0.1


@njit(cache=False)
def _mass(par, q, M):
    M[0, 0] = 2.0 + math.sin(q[0])
    M[1, 1] = 1.0


@njit(cache=False)
def _forces(par, q, v, t, D, need_jac):
    D[0, 0] = -par[0] * q[0] - par[1] * v[0]
    D[1, 0] = -1.0
    if need_jac:
        D[0, 1] = -par[0]      # dh/dq
        D[0, 3] = -par[1]      # dh/dv


@njit(cache=False)
def _contacts(par, q, t, G, need_gap, need_T):
    # contact 0: the floor y >= 0; contact 1: a wall at x = 1 + par[2] t, closing from the right
    if need_gap:
        G[0, 0] = q[1]
        G[1, 0] = 1.0 + par[2] * t - q[0]
    G[0, 4] = 1.0
    G[1, 1] = par[2]
    G[1, 3] = -1.0
    if need_T:
        G[0, 5] = 1.0          # never read: contact 0 is frictionless
        G[1, 6] = 1.0


@njit(cache=False)
def _drift(par, q, v, t, Dr):
    Dr[0, 0] = 0.0


class _Toy(CompiledScene):
    ndof = 2
    mu = np.array([0.0, 0.4])
    restitution = np.zeros(2)

    def compiled_model(self):
        return CompiledModel(_mass, _forces, _contacts, _drift, [K_SPRING, C_DAMP, WALL_SPEED],
                             2, 2, False, True)


def test_every_method_unpacks_the_compiled_outputs():
    toy = _Toy()
    q, v, t = np.array([0.3, 0.2]), np.array([-0.7, 1.1]), 2.0
    np.testing.assert_array_equal(toy.mass(q), np.diag([2.0 + math.sin(0.3), 1.0]))
    np.testing.assert_array_equal(toy.forces(q, v, t), [-K_SPRING * 0.3 + C_DAMP * 0.7, -1.0])
    K, C = toy.force_jacobians(q, v, t)
    np.testing.assert_array_equal(K, [[-K_SPRING, 0.0], [0.0, 0.0]])
    np.testing.assert_array_equal(C, [[-C_DAMP, 0.0], [0.0, 0.0]])
    np.testing.assert_array_equal(toy.gaps(q, t), [0.2, 1.0 + WALL_SPEED * t - 0.3])
    WN, wN, WT, wT = toy.contact_jacobians(q, t)
    np.testing.assert_array_equal(WN, [[0.0, 1.0], [-1.0, 0.0]])
    np.testing.assert_array_equal(wN, [0.0, WALL_SPEED])
    # one tangential row: the frictional contact's only
    np.testing.assert_array_equal(WT, [[0.0, 1.0]])
    np.testing.assert_array_equal(wT, [0.0])
    wNbar, wTbar = toy.contact_drift(q, v, t)
    assert wNbar.shape == (2,) and wTbar.shape == (1,)


def test_the_arrays_returned_are_the_callers():
    toy = _Toy()
    q = np.array([0.3, 0.2])
    toy.gaps(q, 0.0)[:] = 99.0
    toy.mass(q)[:] = 99.0
    np.testing.assert_array_equal(toy.gaps(q, 0.0), [0.2, 0.7])
    assert toy.mass(q)[1, 1] == 1.0


def test_a_pickled_scene_evaluates_the_same():
    toy = _Toy()
    q = [0.3, 0.2]                              # a list is taken as well as an array
    before = toy.gaps(q, 1.0)
    again = pickle.loads(pickle.dumps(toy))
    np.testing.assert_array_equal(again.gaps(q, 1.0), before)


def test_a_model_of_another_size_is_refused_by_name():
    class Wrong(_Toy):
        ndof = 3

    with pytest.raises(MoreauError, match="ndof=2.*ndof=3"):
        Wrong().gaps(np.zeros(3), 0.0)
