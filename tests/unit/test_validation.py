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


# ---- check_integer: the one count check (steps, iterations, quadrature sizes) -----------------
def test_integers_pass_and_are_returned_as_int():
    import numpy as np
    from rough_contact.validation import check_integer
    assert check_integer("steps", 3, lo=1) == 3
    v = check_integer("steps", np.int64(7), lo=1)
    assert v == 7 and type(v) is int
    assert check_integer("n_quad", 400, lo=4, hi=400) == 400
    assert check_integer("first_iteration", 0, lo=0) == 0


@pytest.mark.parametrize("value, words", [
    (0, "steps = 0 is invalid: it must be an integer >= 1"),
    (2.0, "steps = 2.0 is invalid: it must be an integer >= 1"),
    (True, "steps = True is invalid"),
    ("3", "steps = '3' is invalid"),
    (None, "steps = None is invalid"),
    (float("nan"), "steps = nan is invalid"),
])
def test_non_integers_and_out_of_range_are_refused_naming_the_count(value, words):
    from rough_contact.validation import check_integer
    with pytest.raises(ValueError, match=words.replace("(", r"\(")):
        check_integer("steps", value, lo=1)


def test_integer_range_and_what_are_in_the_message():
    from rough_contact.validation import check_integer
    with pytest.raises(ValueError, match=r"n_quad = 401 is invalid: it must be an integer in "
                                         r"\[4, 400\]"):
        check_integer("n_quad", 401, lo=4, hi=400)
    with pytest.raises(ValueError, match=r"first_iteration = -1 is invalid: it must be an "
                                         r"integer >= 0 \(Newton iteration\)"):
        check_integer("first_iteration", -1, lo=0, what="Newton iteration")


@pytest.mark.parametrize("call, words", [
    ("load_unload_factors", "n_load = 2.0 is invalid"),
    ("population", "n_quad = 12.5 is invalid"),
    ("stick_front", "max_iterations = 0 is invalid"),
])
def test_call_sites_use_the_shared_integer_check(call, words):
    """Counts given as floats are refused where they enter (they were silently truncated or
    accepted before the check was shared)."""
    import numpy as np
    with pytest.raises(ValueError, match=words):
        if call == "load_unload_factors":
            from rough_contact.solver.loading import load_unload_factors
            load_unload_factors(2.0)
        elif call == "population":
            from rough_contact.micro.population import _check_nquad
            _check_nquad(12.5)
        else:
            from rough_contact.stick_front import stick_front
            r = np.linspace(0.1, 1.0, 3)
            stick_front(r, np.ones(3), np.zeros(3), 0.3, np.ones(3), np.ones(3, bool),
                        np.zeros(3, bool), max_iterations=0)
