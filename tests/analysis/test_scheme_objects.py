"""The analyses take a scheme as its options object, as they take it by name (issue 35)."""

import numpy as np
import pytest

from moreau.analysis import steady_state
from moreau.analysis.compare import other_schemes
from moreau.analysis.scheme_settings import Scheme, make_scheme
from moreau.errors import InputError
from moreau.integrators.compliant import CompliantRadau
from moreau.integrators.moreau_jean import MoreauJean
from moreau.integrators.schatzman_paoli import SchatzmanPaoli
from moreau.integrators.studer_extrapolation import StuderExtrapolation
from moreau.integrators.time_discontinuous_galerkin import TimeDiscontinuousGalerkin


def test_make_scheme_of_an_options_object_is_that_of_its_name():
    assert make_scheme(MoreauJean.Options(theta=0.5), steps_per_period=500) == \
        make_scheme("moreau-jean", theta=0.5, steps_per_period=500)
    # the default theta of the object is Moreau-Jean's, 1
    assert make_scheme(MoreauJean.Options()) == make_scheme("moreau-jean")
    assert make_scheme(CompliantRadau.Options(stiffness=1e5)) == \
        make_scheme("compliant-radau", options={"stiffness": 1e5})
    assert Scheme(TimeDiscontinuousGalerkin.Options(degree=1), steps_per_period=100) == \
        Scheme("time-discontinuous-galerkin", steps_per_period=100, options={"degree": 1})


def test_an_analysis_refuses_the_step_and_a_theta_given_twice():
    with pytest.raises(InputError, match=r"^`h` is set by `steps_per_period`"):
        Scheme(MoreauJean.Options(h=0.01), steps_per_period=100)
    with pytest.raises(InputError, match="`theta` is given by the options object"):
        make_scheme(MoreauJean.Options(theta=0.5), theta=1.0)
    with pytest.raises(InputError, match=r"^`h` is set by `steps_per_period`"):
        steady_state.find_steady_state(object.__new__(_Drive), SchatzmanPaoli.Options(h=0.1))


class _Drive(steady_state.Scene):
    """Only a Scene instance: the step is refused before the scene is looked at."""


def test_find_steady_state_passes_an_object_on_as_a_call_by_name_does():
    # Moreau-Jean's own solver takes its options as keywords, any other scheme's shooting as
    # scheme_options; the step is always steps_per_period
    name, kw = steady_state._scheme_object(MoreauJean.Options(theta=0.5, lcp_method="lemke"),
                                           {"steps_per_period": 200})
    assert (name, kw) == ("moreau-jean", {"lcp_method": "lemke", "theta": 0.5,
                                          "steps_per_period": 200})
    name, kw = steady_state._scheme_object(SchatzmanPaoli.Options(lcp_method="lemke"),
                                           {"steps_per_period": 200,
                                            "scheme_options": {"save_every": 2}})
    assert (name, kw) == ("schatzman-paoli", {"steps_per_period": 200, "scheme_options": {
        "lcp_method": "lemke", "save_every": 2}})


def test_compare_runs_an_options_object_with_its_options():
    rows = other_schemes(None, quick=True, names=[TimeDiscontinuousGalerkin.Options(degree=1)])
    assert rows == [("time-discontinuous-galerkin", "steps_per_period", (100, 300, 1000),
                     {"degree": 1})]
    # the setting compare varies cannot be fixed by the object
    with pytest.raises(InputError, match="`tol` is the setting compare varies"):
        other_schemes(None, names=[StuderExtrapolation.Options(tol=1e-7)])


@pytest.mark.slow
def test_a_steady_state_of_an_options_object_is_that_of_its_name():
    from moreau.scenes.friction_drive import FrictionDrive
    a = steady_state.find_steady_state(FrictionDrive(frequency=20.0), "moreau-jean", theta=0.5,
                                       steps_per_period=200)
    b = steady_state.find_steady_state(FrictionDrive(frequency=20.0),
                                       MoreauJean.Options(theta=0.5), steps_per_period=200)
    assert a.displacement_per_period == b.displacement_per_period
    np.testing.assert_array_equal(a.state0, b.state0)
