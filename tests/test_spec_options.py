"""One reader of the ``key=value,...`` options of a wear spec and of a fault spec
(faultgen.operation.spec_options): both specs refuse a malformed option with the same words, each
quoting its own spec and form, and read their options in order."""

import re

import pytest

from faultgen.operation.faults import FaultSpec
from faultgen.operation.spec_options import key_values
from faultgen.operation.wear import parse_wear

WEAR_FORM = "the form is AXIS:KIND:PERCENT[:key=value,...]"
FAULT_FORM = "the form is EFFECT:AXIS:PARAMETER:FINAL[:key=value,...]"


def _refuse(reason: str) -> ValueError:
    return ValueError(f"refused: {reason}")


def test_options_are_read_in_order_stripped_and_repeated_keys_kept():
    assert list(key_values(" kind = exp4 ,onset=40, onset=41", _refuse)) == [
        ("kind", "exp4"), ("onset", "40"), ("onset", "41")]
    assert list(key_values("shape=2", _refuse)) == [("shape", "2")]


@pytest.mark.parametrize("option", ["shape", "=2", "shape=", " ", "shape:2"])
def test_a_malformed_option_is_refused_naming_it(option):
    with pytest.raises(ValueError, match=rf"^refused: option {re.escape(repr(option))} is not key=value$"):
        list(key_values(f"onset=3,{option}", _refuse))


def test_options_are_read_lazily_so_an_earlier_bad_value_is_said_first():
    read = key_values("onset=3,shape", _refuse)
    assert next(read) == ("onset", "3")  # the malformed second option is not reached yet
    with pytest.raises(ValueError, match="option 'shape' is not key=value"):
        next(read)


@pytest.mark.parametrize("option", ["shape", "=2", "shape=", ""])
def test_wear_and_fault_specs_refuse_a_malformed_option_in_the_same_words(option):
    said = f"option {option!r} is not key=value"
    wear = f"2:logistic:10:{option}"
    with pytest.raises(ValueError) as wear_error:
        parse_wear(wear, 100)
    assert str(wear_error.value).startswith(f"bad wear spec {wear!r}: {said}; {WEAR_FORM}")
    fault = f"backlash:2:width:0.01:{option}"
    with pytest.raises(ValueError) as fault_error:
        FaultSpec.parse(fault)
    assert str(fault_error.value).startswith(f"bad fault spec {fault!r}: {said}; {FAULT_FORM}")


def test_each_spec_still_converts_its_own_values_in_the_order_given():
    with pytest.raises(ValueError, match=r"option shape=wide is not a number"):
        parse_wear("2:logistic:10:shape=wide,shape", 100)
    with pytest.raises(ValueError, match=r"option onset=4\.5 is not a whole cycle"):
        FaultSpec.parse("backlash:2:width:0.01:onset=4.5,x")
    spec = FaultSpec.parse("backlash:2:width:0.01: kind=exp4 , onset=40,start=0.001")
    assert (spec.kind, spec.onset, spec.start) == ("exp4", 40, 0.001)
    assert parse_wear("3:logistic:10:shape=2", 100)[1].params == {"shape": 2.0}
