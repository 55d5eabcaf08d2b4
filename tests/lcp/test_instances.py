"""Every method on the shared instance list, with a tolerance per method."""

import numpy as np
import pytest

from moreau.lcp import (
    INFEASIBLE,
    NOT_APPLICABLE,
    SOLVED,
    lcp_residual,
    solve_lcp,
)
from moreau.lcp.qp import qp_formulation

from .conftest import TOL, assert_complementary, assert_farkas, instances

INSTANCES = instances()
IDS = [i.name for i in INSTANCES]


def test_instance_names_are_unique_and_cover_the_issue():
    names = set(IDS)
    assert len(names) == len(IDS)
    for needed in ("cycling", "cps-4.4.16", "handbook-10.2.1", "handbook-10.2.2-many", "no-solution",
                   "murty-8", "pmatrix-2", "pmatrix-300", "psd-10-rank4", "friction-1", "friction-5",
                   "friction-50"):
        assert needed in names
    assert any(n.startswith("handbook-10.2.9") for n in names)
    assert any(n.startswith("copositive") or n.startswith("lp-") for n in names)


@pytest.mark.parametrize("inst", [i for i in INSTANCES if i.z is not None], ids=lambda i: i.name)
def test_known_answers_check_out_by_substitution(inst):
    # the data in instances.py are verified here, independently of any solver
    assert lcp_residual(inst.M, inst.q, inst.z) <= 1e-14
    if inst.w is not None:
        np.testing.assert_allclose(inst.M @ inst.z + inst.q, inst.w, atol=1e-12)


@pytest.mark.parametrize("inst", INSTANCES, ids=IDS)
def test_lemke(inst):
    res = solve_lcp(inst.M, inst.q, method="lemke", max_iter=inst.max_iter)
    assert np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w))
    if inst.expect == "ray":
        # both "ray" instances have a row with M_i <= 0 and q_i < 0, so
        # the ray must come back as a proof of infeasibility
        assert res.status == INFEASIBLE
        assert not res.success
        assert res.ray is not None and np.all(np.isfinite(res.ray))
        assert_farkas(inst.M, inst.q, res.certificate)
        return
    assert res.status == SOLVED, res.message
    assert res.residual <= TOL["lemke"]
    assert_complementary(inst.M, inst.q, res.z, TOL["lemke"])
    scale = 1.0 + np.max(np.abs(res.z))
    if inst.z is not None:
        np.testing.assert_allclose(res.z, inst.z, rtol=0, atol=1e-9 * scale)
    if inst.w is not None:
        np.testing.assert_allclose(res.w, inst.w, rtol=0, atol=1e-9 * scale)
    if inst.pivots is not None:
        assert res.pivots == inst.pivots


@pytest.mark.parametrize("inst", INSTANCES, ids=IDS)
def test_qp(inst):
    res = solve_lcp(inst.M, inst.q, method="qp", friction=inst.layout)
    assert np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w))
    form = qp_formulation(inst.M, inst.layout)
    if np.all(inst.q >= 0):
        assert res.success
        return
    if form == "none":
        assert res.status == NOT_APPLICABLE
        assert "friction" in res.message
        return
    if inst.expect == "ray":
        assert not res.success
        return
    assert res.status == SOLVED, res.message
    assert res.residual <= TOL["qp"]
    assert_complementary(inst.M, inst.q, res.z, TOL["qp"])
    scale = 1.0 + np.max(np.abs(res.z))
    if inst.w is not None:
        np.testing.assert_allclose(res.w, inst.w, rtol=0, atol=1e-6 * scale)
    if inst.z is not None and inst.unique:
        np.testing.assert_allclose(res.z, inst.z, rtol=0, atol=1e-6 * scale)


@pytest.mark.parametrize("inst", INSTANCES, ids=IDS)
def test_auto(inst):
    res = solve_lcp(inst.M, inst.q, method="auto", max_iter=inst.max_iter, friction=inst.layout)
    assert np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w))
    if inst.expect == "ray":
        # Lemke's proof stands: no QP is asked
        assert res.status == INFEASIBLE and not res.success
        assert res.path == ("lemke",) and not res.fallback_used
        assert_farkas(inst.M, inst.q, res.certificate)
        return
    assert res.success, res.message
    assert res.residual <= TOL["auto"]
    assert_complementary(inst.M, inst.q, res.z, TOL["auto"])
    # Lemke solves every solvable instance of the list, so no fallback ran
    assert res.path == ("lemke",) and not res.fallback_used


def test_many_solutions_instance_lands_on_the_solution_segment():
    inst = next(i for i in INSTANCES if i.name == "handbook-10.2.2-many")
    for method in ("lemke", "qp"):
        res = solve_lcp(inst.M, inst.q, method=method)
        assert res.success
        assert res.z.sum() == pytest.approx(1.0, abs=1e-8)
        assert np.all(res.z >= -1e-12)
