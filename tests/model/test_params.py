"""The parameter declarations (moreau.model.params): one declaration gives a field's check,
its docstring entry and its registry Parameter."""

import dataclasses
import math
import pickle

import pytest

from moreau.errors import InputError
from moreau.model.params import (MASS, MU, POSITIVE, Declared, open_interval, param,
                                 whole_number)
from moreau.model.registry import Parameter, parameters_of


@dataclasses.dataclass(frozen=True)
class CartParams(Declared):
    """SI parameters of a cart.

    {attributes}

    Examples
    --------
    >>> CartParams().wheels
    4
    """

    mass: float = MASS(2.0, "Mass of the cart")
    wheels: int = param(4, "", whole_number(3, 8), "Number of wheels")
    mu: float = MU(0.0, note="Rolling carts have little.")
    tilt: float = param(0.1, "rad", open_interval(0.0, math.pi / 2, "0, pi/2"), "Tilt")
    axle: float = param(0.5, "m", POSITIVE, "Axle length")

    def __post_init__(self):
        super().__post_init__()
        if self.axle > 10.0 * self.mass:
            raise InputError("`axle` must be at most 10 `mass` here")


@dataclasses.dataclass(frozen=True)
class TrailerParams(CartParams):
    """A cart that carries a load."""

    mass: float = MASS(5.0, "Mass of the trailer")
    load: float = param(1.0, "kg", POSITIVE, "Load")


@pytest.mark.parametrize("bad, message", [
    ({"mass": 0}, "`mass` must be > 0, got 0.0"),
    ({"wheels": 2.5}, "`wheels` must be a whole number in [3, 8], got 2.5"),
    ({"mu": -1.0}, "`mu` must be >= 0, got -1.0"),
    ({"tilt": 2.0}, "`tilt` must be in the open interval (0.0, 1.5707963267948966), got 2.0"),
    ({"axle": "1"}, "`axle` must be a real number, got '1' (a str)"),
    ({"axle": 30.0}, "`axle` must be at most 10 `mass` here"),
])
def test_a_declared_rule_refuses_by_name_with_the_validators_message(bad, message):
    with pytest.raises(InputError) as err:
        CartParams(**bad)
    assert str(err.value) == message


def test_the_rules_keep_what_they_return_and_the_dataclass_behaves_as_one():
    p = CartParams(mass=3, wheels=5.0)
    assert (p.mass, type(p.mass), p.wheels, type(p.wheels)) == (3.0, float, 5, int)
    assert pickle.loads(pickle.dumps(p)) == p
    assert dataclasses.replace(p, mu=0.2).mu == 0.2
    with pytest.raises(InputError, match="`mu` must be >= 0"):
        dataclasses.replace(p, mu=-0.2)
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.mass = 1.0


def test_the_docstring_lists_each_field_with_its_unit_and_rule_in_place():
    doc = CartParams.__doc__
    assert doc.index("Attributes") < doc.index("Examples")
    assert "    mass : float\n        Mass of the cart [kg], > 0.\n" in doc
    assert "    wheels : int\n        Number of wheels, a whole number in [3, 8].\n" in doc
    assert ("    mu : float\n        Coulomb friction coefficient, >= 0. Rolling carts have "
            "little.\n") in doc
    assert "    tilt : float\n        Tilt [rad], in (0, pi/2).\n" in doc
    # a subclass lists every field, a field declared again in its base's place
    names = [line.split(" : ")[0].strip() for line in TrailerParams.__doc__.splitlines()
             if " : " in line]
    assert names == ["mass", "wheels", "mu", "tilt", "axle", "load"]
    assert "Mass of the trailer [kg], > 0." in TrailerParams.__doc__


def test_parameters_of_reads_units_defaults_and_docs_from_the_declarations():
    params = parameters_of(TrailerParams, extra=(Parameter("speed", "m/s", 1.0, "Speed"),))
    assert params[:3] == (Parameter("speed", "m/s", 1.0, "Speed"),
                          Parameter("mass", "kg", 5.0, "Mass of the trailer"),
                          Parameter("wheels", "", 4, "Number of wheels"))
    assert [p.unit for p in params[3:]] == ["", "rad", "m", "kg"]


def test_an_undeclared_field_is_refused_when_the_class_is_made():
    with pytest.raises(TypeError, match="the field `height` of BadParams must be declared"):
        @dataclasses.dataclass(frozen=True)
        class BadParams(Declared):
            height: float = 1.0
