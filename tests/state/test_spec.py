"""A builder's contract: ``Spec.check`` refuses a domain with a field missing or of the wrong kind."""
import numpy as np
import pytest

from infomarket.errors import InternalError
from infomarket.state.spec import Spec, fields

SPEC = Spec("demo", fields("engine", [("pos", "float64", "n,2", "positions"),
                                      ("kind", "int64", "n", "kinds"),
                                      ("gain", "float", "", "a scalar"),
                                      ("on", "bool", "", "a flag"),
                                      ("count", "int", "", "a count")]))


def good():
    return {"pos": np.zeros((3, 2)), "kind": np.zeros(3, np.int64), "gain": 1.5, "on": True, "count": 2}


def test_a_domain_as_specified_is_built():
    built = SPEC.build(good())
    assert built.gain == 1.5 and built.pos.shape == (3, 2)


@pytest.mark.parametrize("change, message", [
    ({"pos": None}, "missing pos"),
    ({"pos": np.zeros((3, 2), np.float32)}, "demo.pos: float32 2-d, spec says float64 2-d"),
    ({"pos": np.zeros(6)}, "demo.pos: float64 1-d, spec says float64 2-d"),
    ({"kind": [0, 1, 2]}, "demo.kind: list, spec says int64 1-d"),
    ({"gain": 1}, "demo.gain: int, spec says float"),
    ({"on": 1}, "demo.on: int, spec says bool"),
    ({"count": True}, "demo.count: bool, spec says int"),  # a bool is an int to isinstance, not here
])
def test_a_field_missing_or_of_the_wrong_kind_is_named(change, message):
    values = {**good(), **change}
    values = {k: v for k, v in values.items() if v is not None}
    with pytest.raises(InternalError, match=message):
        SPEC.check(values)
