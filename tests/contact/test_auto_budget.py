"""``auto`` above the crossover: NSGS within its budget (plain, then over-relaxed), else the dense LCP."""

import numpy as np

from moreau.contact import ContactProblem, solve
from moreau.contact._sparse import chain_impact_problem
from moreau.contact.solvers.auto import PLAIN_SWEEPS, auto_budget


def _pressed_chain(n_balls):
    W, q, mu, r = chain_impact_problem(n_balls, e=1.0)
    return ContactProblem(W.toarray()[0::2, 0::2], q[0::2], np.zeros(n_balls - 1), 0.0), r[0::2]


def test_a_step_nsgs_cannot_finish_in_its_budget_goes_to_lemke_and_says_so():
    # the pressed chain of 100 balls needs 12 740 plain sweeps: more than auto_budget(99) = 1190
    pb, exact = _pressed_chain(100)
    assert auto_budget(99) == 1190
    sol = solve(pb)
    assert sol.path == ("nsgs", "lemke") and sol.success
    assert np.max(np.abs(sol.pN - exact)) <= 1e-12


def test_the_over_relaxed_sweeps_finish_what_plain_ones_cannot_in_the_same_budget():
    pb, exact = _pressed_chain(100)
    plain = solve(pb, "nsgs", max_iter=6000)
    assert plain.status == "max-iter"
    sol = solve(pb, max_iter=6000)
    assert sol.path == ("nsgs",) and sol.success and sol.residual <= 1e-8
    assert PLAIN_SWEEPS < sol.iterations < 6000
