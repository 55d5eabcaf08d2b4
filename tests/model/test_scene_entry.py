"""A registry entry reads what its factory and case already state: parameters, reference, tolerance."""

from dataclasses import dataclass

import pytest

from moreau.errors import InputError
from moreau.model import registry
from moreau.model.params import MASS, Declared, param
from moreau.model.registry import Parameter, SceneEntry, parameters_of
from moreau.model.scene import FromParams, params_with


@dataclass(frozen=True)
class CartParams(Declared):
    """SI parameters of a cart."""

    mass: float = MASS(2.0, "Mass of the cart")
    speed: float = param(0.5, "m/s", None, "Launch speed")

    sweepable = ("speed",)


class Cart(FromParams):
    """A cart (its parameters only, for the test)."""

    Params = CartParams

    def _setup(self, p):
        pass


def cart_of(params=None, **overrides):
    """A function factory of the cart's parameters."""
    return params_with(CartParams, params, overrides)


cart_of.Params = CartParams


def loose_cart(mass=2.0):
    return mass


@pytest.mark.parametrize("factory", [Cart, cart_of])
def test_the_parameters_come_from_the_factorys_parameter_class(factory):
    entry = SceneEntry(name="cart", factory=factory, description="a cart")
    assert entry.parameters == parameters_of(CartParams)
    assert entry.parameter_names() == ("mass", "speed")
    assert entry.defaults() == {"mass": 2.0, "speed": 0.5}
    assert entry.sweepable == ("speed",)


def test_the_sweepable_parameters_come_from_the_parameter_class_unless_given():
    assert SceneEntry(name="cart", factory=Cart, description="a cart").sweepable == ("speed",)
    assert SceneEntry(name="cart", factory=Cart, description="a cart",
                      sweepable=("mass",)).sweepable == ("mass",)
    assert SceneEntry(name="loose", factory=loose_cart, description="a cart",
                      parameters=()).sweepable == ()


class CartCase:
    """A comparison case stating its reference and tolerance (the registry reads them)."""

    listed_reference = "exact"
    mj_tolerance = 3e-2


def test_the_reference_and_tolerance_are_read_from_the_case_unless_given():
    entry = SceneEntry(name="cart", factory=Cart, description="a cart", case=CartCase)
    assert entry.reference == "exact" and entry.mj_tolerance == 3e-2
    assert registry.describe(entry)["reference"] == "exact"
    given = SceneEntry(name="cart", factory=Cart, description="a cart", case=CartCase,
                       reference="cart-walker", mj_tolerance=1e-3)
    assert given.reference == "cart-walker" and given.mj_tolerance == 1e-3
    # without a case: the generic event-driven reference and the registry's tolerance
    bare = SceneEntry(name="cart", factory=Cart, description="a cart")
    assert bare.reference is None and bare.mj_tolerance == registry.MJ_TOLERANCE
    assert registry.describe(bare)["reference"] == "event-driven-generic"


def test_the_shipped_cases_state_what_their_entries_list():
    from moreau.analysis.cases import CompareCase
    for entry in registry.entries():
        if entry.case is not None:
            assert issubclass(entry.case, CompareCase)
            assert entry.mj_tolerance == entry.case.mj_tolerance > 0
    assert registry.get_entry("sphere-incline").reference == "exact"        # a closed-form path
    assert registry.get_entry("ball-chain-3d").mj_tolerance == 1e-3      # the chains' own
    assert registry.get_entry("friction-drive").reference == "friction-drive-walker"  # given
    assert registry.get_entry("rocking-block-built").sweepable == ("mu", "tilt", "width", "height")


def test_given_parameters_win_over_the_factorys_class():
    extra = (Parameter("frequency", "Hz", 10.0, "drive frequency"),)
    entry = SceneEntry(name="cart", factory=Cart, description="a cart",
                       parameters=parameters_of(CartParams, extra=extra))
    assert entry.parameter_names() == ("frequency", "mass", "speed")


def test_a_factory_without_a_parameter_class_needs_its_parameters_given():
    with pytest.raises(InputError, match=r"`parameters` of scene 'loose' must be given: its "
                                         r"factory loose_cart has no parameter class `Params`"):
        SceneEntry(name="loose", factory=loose_cart, description="a cart")
    given = (Parameter("mass", "kg", 2.0, "Mass"),)
    assert SceneEntry(name="loose", factory=loose_cart, description="a cart",
                      parameters=given).parameters == given


def test_an_entry_without_a_description_is_refused_by_name():
    with pytest.raises(InputError, match="`description` of scene 'cart' must be given"):
        SceneEntry(name="cart", factory=Cart)


def test_an_entry_with_derived_parameters_registers_and_builds():
    entry = registry.register_scene(SceneEntry(name="test-cart", factory=Cart,
                                               description="a cart"))
    try:
        assert registry.get_entry("test-cart") is entry
        assert registry.make_scene("test-cart", mass=4.0).params == CartParams(mass=4.0)
        assert registry.describe(entry)["parameters"][1] == {
            "name": "speed", "unit": "m/s", "default": 0.5, "doc": "Launch speed"}
    finally:
        registry._REGISTRY.pop("test-cart")
