"""Guards at the model's edges during load stepping (serial and ``mpirun -n 2``).

* model validity: a converged increment whose interface points lie beyond the normal law's
  range (separation below the table's lowest knot: the stiff continuation, not the asperity
  model) is reported per increment, warned about by default and an error on request; the
  count is checked against the normal law's own ``below_validity`` evaluated independently at
  the converged jump;
* a non-finite initial guess is refused before the first solve.

Coarse quarter punch (P1, 732 DOFs), elastic normal law, frictionless. Units: mm, N, MPa.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.scenes import flat_punch
from rough_contact.solver.loading import (
    ModelValidityError,
    ModelValidityWarning,
    load_path,
    load_unload_factors,
)

COARSE = dict(mesh_size=20.0, contact_size=2.5, order=1, normal_law="elastic", case="none",
              steps=2)


def _model(total_force):
    return flat_punch.build(MPI.COMM_WORLD, total_force=total_force, **COARSE)


def _independent_count(m) -> int:
    """Points below the normal law's validity at the converged jump, from the law's table."""
    ci = m.interface
    h = m.law.h0 + ci.jump(m.problem.u)[:, 0]
    return MPI.COMM_WORLD.allreduce(m.law.normal.count_below_validity(h), op=MPI.SUM)


def test_paper_load_is_within_validity():
    m = _model(flat_punch.TOTAL_FORCE)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelValidityWarning)
        incs = list(load_path(m.problem, m.solver, load_unload_factors(2, 0), verbose=False))
    assert [i.n_beyond_validity for i in incs] == [0, 0]
    assert _independent_count(m) == 0


def test_overload_beyond_validity_warns_with_the_count():
    m = _model(1e7)      # 10^4 x the paper's load: every point beyond the table (A/A0 limit)
    n = m.interface.n_points_global     # 126 with gmsh 4.8's mesh, 132 with gmsh 4.13's
    with pytest.warns(ModelValidityWarning, match=rf"{n} of {n} interface points .* beyond the "
                      r"interface law's range of validity") as record:
        incs = list(load_path(m.problem, m.solver, load_unload_factors(2, 0), verbose=False))
    assert len(incs) == 2 and len(record) == 2          # one warning per increment
    n_ref = _independent_count(m)
    assert n_ref > 0
    assert incs[-1].n_beyond_validity == n_ref
    assert f"load factor 1: {n_ref} of {incs[-1].n_points}" in str(record[-1].message)


def test_overload_with_validity_error_stops_after_the_first_increment():
    m = _model(1e7)
    path = load_path(m.problem, m.solver, load_unload_factors(2, 0), verbose=False,
                     validity="error")
    with pytest.raises(ModelValidityError, match="load factor 0.5: .* beyond the interface "
                       "law's range of validity.*this increment is committed") as err:
        next(path)
    assert err.value.load_factor == 0.5
    assert err.value.n_beyond == _independent_count(m) > 0
    assert m.problem.load_factor == 0.5        # the converged increment is kept


def test_bad_validity_policy_is_refused():
    m = _model(flat_punch.TOTAL_FORCE)
    with pytest.raises(ValueError, match="validity = 'loud' is invalid: it must be one of warn, "
                       "error, ignore"):
        next(load_path(m.problem, m.solver, [0.5], validity="loud"))


@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_non_finite_initial_guess_is_refused_before_solving(value):
    m = _model(flat_punch.TOTAL_FORCE)
    comm = MPI.COMM_WORLD
    if comm.rank == comm.size - 1 and m.problem.u.x.array.size:
        m.problem.u.x.array[0] = value          # one bad value on one rank is enough
    m.problem.u.x.scatter_forward()
    calls = []
    solve = m.solver.solve
    m.solver.solve = lambda *a, **k: (calls.append(1), solve(*a, **k))[1]
    with pytest.raises(ValueError, match=r"initial guess \(displacement u\) has [1-9]\d* "
                       r"non-finite value\(s\) \(first: (nan|inf) at local DOF"):
        next(load_path(m.problem, m.solver, [0.5], verbose=False))
    assert not calls                              # refused before the first solve
