"""Canonical descriptions of laws and other set-up objects (rough_contact.fingerprint), the
fingerprint a checkpoint records (issue 24: a restart with another friction law was accepted
because only the class name was stored).

Checked against values written by hand: floats compare to round-off (repr written), arrays by
content to round-off, a field declared compare=False is not part of the identity, the user law of
docs/writing_a_law.md (a frozen dataclass) is described from its fields without any code of its
own, an object that cannot be described gets its class name and a warning, not a crash.
"""

from __future__ import annotations

import re
import sys
import types
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from rough_contact.fingerprint import UndescribedWarning, describe, differences
from rough_contact.interface.friction import OrthotropicSlipHardening
from rough_contact.interface.tangential import TangentialStiffness

DOC = Path(__file__).resolve().parents[2] / "docs" / "writing_a_law.md"


def _friction(mu=0.5):
    return OrthotropicSlipHardening(mu_macro=(mu, mu), mu_initial_ratio=(0.5, 0.5),
                                    hardening=(275.0, 275.0), potential_axes=(0.125, 0.125))


def test_dataclass_law_is_described_by_its_fields_floats_to_round_off():
    d = describe(_friction())
    assert d["type"] == "rough_contact.interface.friction.OrthotropicSlipHardening"
    assert d["mu_macro"] == ["0.5", "0.5"] and d["hardening"] == ["275.0", "275.0"]
    assert describe(_friction()) == d                      # stable
    # to round-off: one unit in the last place is the same law, the 9th digit is another
    assert differences(d, describe(_friction(np.nextafter(0.5, 1.0)))) == []
    near = describe(_friction(0.50000001))
    assert differences(d, near) == ["mu_macro[0]: 0.5 in the checkpoint, 0.50000001 now",
                                    "mu_macro[1]: 0.5 in the checkpoint, 0.50000001 now"]
    assert differences(d, describe(_friction(0.3)))[0] == ("mu_macro[0]: 0.5 in the checkpoint, "
                                                           "0.3 now")
    assert differences(describe(TangentialStiffness((0.7, 0.7))),
                       describe(TangentialStiffness((0.7, 1.0)))) == [
        "kt_over_kn[1]: 0.7 in the checkpoint, 1.0 now"]
    # another class with the same fields is another law
    assert any(k.startswith("type:") for k in differences(d, {**d, "type": "x.Other"}))


def test_arrays_by_content_and_compare_false_fields_left_out():
    @dataclass(frozen=True)
    class Table:
        knots: np.ndarray
        small: np.ndarray
        info: dict = field(default_factory=dict, compare=False)

    a = Table(np.linspace(0.0, 1.0, 100), np.array([1.0, 2.0]), info={"wall_time": 1.0})
    b = Table(np.linspace(0.0, 1.0, 100), np.array([1.0, 2.0]), info={"wall_time": 2.0})
    assert describe(a) == describe(b)                     # build statistics do not count
    assert "info" not in describe(a)
    assert describe(a)["small"] == ["1.0", "2.0"]
    assert describe(a)["knots"]["shape"] == [100] and len(describe(a)["knots"]["sha256"]) == 64
    c = Table(np.linspace(0.0, 1.0, 100) ** 2, np.array([1.0, 2.0]))
    diff = differences(describe(a), describe(c))
    assert len(diff) == 1 and diff[0].startswith("knots: array float64(100,) sha256 ")


def test_functions_by_name_and_closure():
    from rough_contact.solver.program import preload_then_cyclic

    one = preload_then_cyclic(2, 1, 8).channels["cyclic"]
    half = preload_then_cyclic(2, 1, 8, amplitude=0.5).channels["cyclic"]
    assert describe(one)["function"].endswith("preload_then_cyclic.<locals>.wave")
    assert differences(describe(one), describe(half)) == ["closure.a: 1.0 in the checkpoint, "
                                                          "0.5 now"]


def test_user_law_of_the_docs_gets_a_fingerprint_from_its_fields():
    block, = re.findall(r"^```python\n(.*?)^```", DOC.read_text(encoding="utf-8"),
                        flags=re.S | re.M)
    mod = types.ModuleType("writing_a_law_example_fingerprint")
    sys.modules[mod.__name__] = mod
    exec(compile(block, str(DOC), "exec"), mod.__dict__)
    law = mod.ExponentialCoulombLaw(p0=1.0, length=1e-3, mu=0.05, kt_over_kn=0.7, g_open=3e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                    # no fallback warning
        d = describe(law)
    assert d["mu"] == "0.05" and d["length"] == "0.001" and d["g_open"] == "0.003"
    other = mod.ExponentialCoulombLaw(p0=1.0, length=1e-3, mu=0.1, kt_over_kn=0.7, g_open=3e-3)
    assert differences(d, describe(other)) == ["mu: 0.05 in the checkpoint, 0.1 now"]


def test_undescribable_object_falls_back_to_its_class_with_a_warning():
    class OpaqueLaw:
        def __init__(self, mu):
            self._mu = mu

    with pytest.warns(UndescribedWarning, match=r"law \(.*OpaqueLaw\) cannot be described"):
        d = describe(OpaqueLaw(0.3), "law")
    assert d == {"type": f"{__name__}.test_undescribable_object_falls_back_to_its_class_"
                         "with_a_warning.<locals>.OpaqueLaw", "undescribed": True}


def test_differences_name_lists_of_another_length_once_and_limit_the_list():
    assert differences(["1.0", "2.0"], ["1.0", "2.0", "3.0"]) == [
        "(top): 2 entries in the checkpoint, 3 now"]
    many = differences({f"k{i}": str(i) for i in range(20)}, {f"k{i}": "x" for i in range(20)},
                       limit=3)
    assert len(many) == 4 and many[-1] == "and 17 more"
    assert differences({"a": None}, {"a": "0.1"}) == ["a: (absent) in the checkpoint, 0.1 now"]


def test_round_off_is_not_a_different_parameter():
    """The same law table built in another process can differ in its last bits (OpenBLAS rounds
    differently on differently aligned data): a restart must not be refused for that, while a
    table that differs beyond round-off, or a parameter changed in its 8th digit, still is."""
    rng = np.random.default_rng(3)
    a = rng.uniform(-5.0, 5.0, (4, 31))
    ulp = a.copy()
    ulp[rng.random(a.shape) < 0.3] *= 1.0 + 2.0 ** -52           # last-bit differences
    assert describe(a)["sha256"] != describe(ulp)["sha256"]
    assert differences(describe({"t": a}), describe({"t": ulp})) == []
    for i, rel in ((7, 1e-6), (0, 1e-7)):                        # a real difference, one entry
        b = a.copy()
        b.flat[i] *= 1.0 + rel
        assert len(differences(describe({"t": a}), describe({"t": b}))) == 1
    assert differences(describe({"mu": 0.3}), describe({"mu": 0.1 + 0.2})) == []
    assert differences(describe({"mu": 0.3}), describe({"mu": 0.30000001})) == \
        ["mu: 0.3 in the checkpoint, 0.30000001 now"]
    assert differences(describe({"law": "elastic"}), describe({"law": "plastic"})) != []
    # a description written before sketches existed is compared by its hash alone
    old = {k: v for k, v in describe(a).items() if k != "sketch"}
    assert differences({"t": old}, describe({"t": ulp})) != []


def test_a_field_added_later_is_described_only_away_from_its_default():
    """A field declared with ``metadata={FINGERPRINT_ADDED: True}`` is left out at its default,
    so a checkpoint written before the field existed matches; any other value is named."""
    import dataclasses

    from rough_contact.fingerprint import FINGERPRINT_ADDED

    @dataclasses.dataclass(frozen=True)
    class Old:
        k: float

    @dataclasses.dataclass(frozen=True)
    class New:
        k: float
        mode: str = dataclasses.field(default="a", metadata={FINGERPRINT_ADDED: True})

    saved = describe(Old(1.0))
    saved["type"] = describe(New(1.0))["type"]             # the same class, an older version
    assert "mode" not in describe(New(1.0))
    assert differences(saved, describe(New(1.0))) == []
    assert differences(saved, describe(New(1.0, mode="b"))) == [
        "mode: (absent) in the checkpoint, b now"]
    # the law that uses it: the default SoftplusPenalty describes as before the field existed
    from rough_contact.interface.penalty import SoftplusPenalty
    assert "first_contact" not in describe(SoftplusPenalty(1e8, 1e-7, 1e7, 0.3))
    assert describe(SoftplusPenalty(1e8, 1e-7, 1e7, 0.3,
                                    first_contact="closure"))["first_contact"] == "closure"
