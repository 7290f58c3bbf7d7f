"""rough_contact.validation.check_scalar, the one input check of every layer (issue 24)."""

from __future__ import annotations

import pytest

from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.validation import check_scalar


def test_numbers_pass_and_are_returned_as_float():
    assert check_scalar("E", 2e5, lo=0.0, unit="MPa") == 2e5
    assert type(check_scalar("n", 3, lo=0)) is float


@pytest.mark.parametrize("value", ["2e5", b"2e5", "nan", None, [1.0]])
def test_strings_and_non_numbers_are_refused_naming_the_quantity(value):
    with pytest.raises(ValueError, match=r"Young's modulus E = .* is invalid"):
        check_scalar("Young's modulus E", value, lo=0.0, unit="MPa")


def test_a_frozen_law_given_a_string_fails_at_construction_not_later():
    """Before: SoftplusPenalty("1e4", ...) was accepted (the check converted a copy) and the
    string stayed in the law until an arithmetic operation failed with a TypeError."""
    with pytest.raises(ValueError, match=r"k_normal = '1e4' is invalid: it must be a number"):
        SoftplusPenalty(k_normal="1e4", width=1e-3)
