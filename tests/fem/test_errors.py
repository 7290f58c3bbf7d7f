"""The interface's hand-offs and failures: law protocol, result contract, collective errors.

Serial and ``mpirun -n 2 python -m mpi4py -m pytest tests/fem/test_errors.py``: every failure
must reach every rank (a rank left waiting in a collective would hang the run).

Units: mm, N, MPa.
"""

from __future__ import annotations

import dataclasses
import types

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx.cpp
import ufl
from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.collective import raise_on_all_ranks
from rough_contact.fem.contact import ContactInterface
from rough_contact.interface.contract import ConvergenceError, LawContractError
from rough_contact.interface.friction import ReturnMappingError
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from test_contact import (LOWER_TOP, UPPER_BOTTOM, interpolate_bodies, smooth_field,  # noqa: E402
                          two_blocks)


class LocalNewtonError(ConvergenceError):
    """A module-level ConvergenceError subclass (importable by name on every rank)."""


def _interface(law, comm=MPI.COMM_WORLD, degree=1):
    msh, tags = two_blocks(comm, n=(2, 2, 1))
    V = compat.vector_space(msh, degree)
    return V, ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law)


# ---------------------------------------------------------------------------- protocol
class _OnlyInitialState:
    def initial_state(self, n):
        return LinearPenalty(1.0).initial_state(n)


class _EvaluateNotCallable(_OnlyInitialState):
    evaluate = 3.0


@pytest.mark.parametrize("law,missing", [(object(), "initial_state, evaluate"),
                                         (_OnlyInitialState(), "evaluate"),
                                         (_EvaluateNotCallable(), "evaluate")])
def test_law_without_the_protocol_is_a_type_error(law, missing):
    with pytest.raises(TypeError, match=f"InterfaceLawProtocol.*missing method\\(s\\) {missing}$"):
        _interface(law)


class _BadInitialState(_OnlyInitialState):
    def initial_state(self, n):
        return np.zeros((n, 2))  # an array, not a LawState (no copy() of the contract's kind)

    def evaluate(self, jump, committed):
        raise AssertionError("never called")


def test_initial_state_must_be_a_law_state():
    with pytest.raises(LawContractError, match="initial_state returned ndarray"):
        _interface(_BadInitialState())


# ---------------------------------------------------------------------------- result contract
class _Counting:
    """Wraps a law: counts evaluate calls, optionally rewrites the first result's fields."""

    def __init__(self, law, **fields):
        self.law, self.fields, self.calls = law, fields, 0

    def initial_state(self, n):
        return self.law.initial_state(n)

    def evaluate(self, jump, committed):
        self.calls += 1
        res = self.law.evaluate(jump, committed)
        new = {k: f(res) for k, f in self.fields.items()}
        return dataclasses.replace(res, **new) if new else res


@pytest.mark.parametrize("field,make,message", [
    ("traction", lambda r: r.traction[:, :2], r"traction has shape \(\d+, 2\)"),
    ("tangent", lambda r: r.tangent[:, :2], r"tangent has shape \(\d+, 2, 3\)"),
    ("contact", lambda r: r.contact.astype(float), "contact has dtype float64"),
    ("dissipation", lambda r: list(r.dissipation), "dissipation must be a numpy array"),
])
def test_first_result_is_checked_naming_the_field(field, make, message):
    law = _Counting(LinearPenalty(1e3, 5e2), **{field: make})
    V, ci = _interface(law)
    with pytest.raises(LawContractError, match=message):
        ci.evaluate(fem.Function(V))
    assert law.calls == 1


class _WrongResultType(_Counting):
    def evaluate(self, jump, committed):
        res = super().evaluate(jump, committed)
        return types.SimpleNamespace(**{f.name: getattr(res, f.name)
                                        for f in dataclasses.fields(res)})


def test_result_must_be_the_contract_law_result():
    """A look-alike with the same fields is not accepted: the contract has ONE LawResult."""
    V, ci = _interface(_WrongResultType(LinearPenalty(1e3)))
    with pytest.raises(LawContractError, match="returned SimpleNamespace; the contract needs "
                                               "rough_contact.interface.contract.LawResult"):
        ci.evaluate(fem.Function(V))


def test_only_the_first_result_is_checked_in_full():
    """Later evaluations cost no contract check: a law that breaks the contract only after its
    first (valid) result is not caught, as documented (finiteness is still checked)."""
    law = _Counting(SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.3))
    V, ci = _interface(law)
    u = fem.Function(V)
    ci.evaluate(u)
    assert ci._result_checked
    law.fields = {"contact": lambda r: r.contact.astype(float)}
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, 1e-3))
    res = ci.evaluate(u)
    assert res.contact.dtype == float and law.calls == 2


def test_non_finite_jump_is_a_convergence_error_before_the_law_is_called():
    law = _Counting(LinearPenalty(1e3))
    V, ci = _interface(law)
    u = fem.Function(V)
    u.x.array[:] = np.nan
    with pytest.raises(ConvergenceError, match="non-finite jump"):
        ci.evaluate(u)
    if ci.n_points:  # a rank with points never calls the law on a non-finite jump
        assert law.calls == 0
    # the cache was not filled by the failure: a finite u evaluates normally
    u.x.array[:] = 0.0
    ci.evaluate(u)
    assert ci.comm.allreduce(law.calls, op=MPI.SUM) >= 1


def test_lifecycle_law_calls():
    """The lifecycle decides when the law runs, no cache: every evaluate calls the law once;
    the residual and the Jacobian assembled after it use that evaluation (no further call);
    after a revert nothing is left to assemble from until the next evaluation."""
    law = _Counting(SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.3))
    V, ci = _interface(law)
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, 1e-3))
    ci.evaluate(u)
    assert law.calls == 1
    b = compat.create_petsc_vector(V)
    ci.assemble_residual(b)
    mass = fem.form(ufl.inner(ufl.TrialFunction(V), ufl.TestFunction(V)) * ufl.dx)
    A = ci.create_matrix(mass)
    ci.assemble_jacobian(A)
    A.assemble()
    assert law.calls == 1
    ci.evaluate(compat.petsc_vector(u))             # the same u again: the law runs again
    assert law.calls == 2
    assert ci.accept(u).done and law.calls == 3   # accept evaluates at the converged iterate
    ci.commit()
    ci.contact_force()                # queries read the last evaluation, also after a commit
    ci.revert()
    with pytest.raises(ValueError, match="not been evaluated"):
        ci.assemble_residual(b)
    assert law.calls == 3


# ---------------------------------------------------------------------------- collective errors
class _RaisesOnOneRank:
    """LinearPenalty that raises ``error`` (a fresh instance per call) on ``rank`` only."""

    def __init__(self, make_error, rank=0):
        self.law, self.make_error, self.rank = LinearPenalty(1e3), make_error, rank
        self.raised = None

    def initial_state(self, n):
        return self.law.initial_state(n)

    def evaluate(self, jump, committed):
        if MPI.COMM_WORLD.rank == self.rank:
            self.raised = self.make_error()
            raise self.raised
        return self.law.evaluate(jump, committed)


@pytest.mark.parametrize("kind", ["convergence", "fatal"])
def test_law_error_on_one_rank_raises_on_every_rank(kind):
    comm = MPI.COMM_WORLD
    make = (lambda: ReturnMappingError("local Newton failed at 3 points")) \
        if kind == "convergence" else (lambda: TypeError("unsupported operand"))
    law = _RaisesOnOneRank(make)
    V, ci = _interface(law)
    with pytest.raises(Exception) as info:
        ci.evaluate(fem.Function(V))
    if comm.rank == law.rank:
        assert info.value is law.raised  # the very object, with its traceback
        assert any(tb.name == "evaluate" for tb in info.traceback)
    elif kind == "convergence":
        assert type(info.value) is ReturnMappingError
        assert str(info.value) == f"rank {law.rank} raised ReturnMappingError: local Newton " \
                                  "failed at 3 points"
    else:
        assert type(info.value) is RuntimeError
        assert str(info.value) == f"rank {law.rank} raised TypeError: unsupported operand"


def test_raise_on_all_ranks_semantics():
    comm = MPI.COMM_WORLD
    last = comm.size - 1
    raise_on_all_ranks(comm, None)  # nobody failed: returns on every rank

    # a ConvergenceError class that cannot be found by name: plain ConvergenceError elsewhere
    class Unnamed(ConvergenceError):
        pass

    mine = Unnamed("x") if comm.rank == last else None
    with pytest.raises(ConvergenceError) as info:
        raise_on_all_ranks(comm, mine)
    if comm.rank == last:
        assert info.value is mine
    else:
        assert type(info.value) is ConvergenceError
        assert str(info.value) == f"rank {last} raised Unnamed: x"

    # a convergence failure on rank 0 and a fatal one on the last rank: fatal everywhere
    if comm.size > 1:
        mine = {0: LocalNewtonError("n"), last: KeyError("k")}.get(comm.rank)
        with pytest.raises(Exception) as info:
            raise_on_all_ranks(comm, mine)
        if comm.rank == last:
            assert info.value is mine
        else:
            assert type(info.value) is RuntimeError and "raised KeyError" in str(info.value)
            assert info.value.__cause__ is mine
