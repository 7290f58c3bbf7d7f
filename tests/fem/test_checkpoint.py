"""Checkpoint and resume of a load path (serial and 2 ranks).

Reference: the same program run without interruption. Two blocks with the paper's rough law
(slip-hardening friction, case b), a preload and one tangential cycle of +-2 um (slip, hardening:
history matters). A run that writes checkpoints and results is stopped after writing the output
of increment 7 but before its checkpoint (the window a kill can hit); a freshly built problem
resumes from the directory: its increments must equal the uninterrupted run's (displacement to
1e-12 of its maximum, dissipation and contact forces to 1e-12 relative), the step numbers
continue, and the output files continue: history.csv, displacement.xdmf and interface.xdmf hold
each increment once and equal the uninterrupted run's files. A checkpoint of another problem, other load factors, or an empty
directory are refused with a clear error. Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import (ContactProblem, Material, PrescribedDisplacement,
                                       SurfaceLoad)
from rough_contact.io import ResultWriter, read_interface_results
from rough_contact.scenes import flat_punch
from rough_contact.scenes.meshes.blocks import two_blocks
from rough_contact.solver.checkpoint import CheckpointError
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import preload_then_cyclic
from rough_contact.solver.snes import SNESSolver
from rough_contact.scenes.defaults import SEATING_STIFFNESS

PROGRAM = preload_then_cyclic(preload_steps=2, cycles=1, steps_per_cycle=8)
_NORMAL = {}


_SCENES = {}


def _model(mesh_size=0.5, case="b", program=None, degree=1):
    comm = MPI.COMM_WORLD
    # built once per size: a second build of a mesh may be partitioned differently on 2 ranks,
    # and a checkpoint resumes only into the partition it was written from
    if mesh_size not in _SCENES:
        _SCENES[mesh_size] = two_blocks(lx=2.0, ly=2.0, h1=1.0, h2=1.0, mesh_size=mesh_size,
                                        order=1)
    scene = _SCENES[mesh_size]
    V = compat.vector_space(scene.mesh, degree)
    clamp = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), fem.locate_dofs_topological(
        V, 2, scene.facet_tags.find(scene.tag("bottom"))), V)
    law, normal = flat_punch.make_law(comm, case=case, normal_law="elastic", seating_pressure=5.0,
                                      normal=_NORMAL.get("n"))
    _NORMAL["n"] = normal
    first, second = scene.contact_pair
    ci = ContactInterface(V, scene.facet_tags, first, second, law=law, bcs=[clamp])
    top = scene.tag("top")
    problem = ContactProblem(
        V, Material(flat_punch.E, flat_punch.NU), [clamp],
        [SurfaceLoad(top, force=(0.0, 0.0, -40.0), channel="preload")],
        facet_tags=scene.facet_tags, interface=ci, seating_tag=first,
        seating_stiffness=SEATING_STIFFNESS,
        prescribed=[PrescribedDisplacement(top, (2e-3, 0.0, 0.0), (0,), channel="cyclic")],
        programs=(program or PROGRAM).channels)
    return problem, SNESSolver(problem, prefix="ck_")


def _record(problem, inc):
    return dict(step=inc.step, lam=inc.load_factor, u=problem.u.x.array.copy(),
                D=inc.dissipation, F=inc.contact_force.copy())


def _csv(path):
    import csv

    with open(path) as f:
        rows = list(csv.DictReader(f))
    skip = {"wall_time_s"}
    return [{k: float(v) for k, v in r.items() if k not in skip and v != ""} for r in rows]


def _xdmf_steps(path):
    """(time values, {time: displacement array}) of a DOLFINx XDMF time series."""
    import os
    import h5py

    from rough_contact.io.files import parse_xdmf

    root = parse_xdmf(path)
    times, data = [], {}
    h5 = os.path.splitext(path)[0] + ".h5"
    with h5py.File(h5, "r") as f:
        for grid in root.iter("Grid"):
            if grid.get("GridType") == "Uniform" and grid.find("Time") is not None:
                t = float(grid.find("Time").get("Value"))
                item = grid.find("Attribute/DataItem").text.strip().partition(":")[2]
                times.append(t)
                data[t] = f[item][...]
    return times, data


def test_resume_reproduces_the_uninterrupted_run(tmp_path):
    comm = MPI.COMM_WORLD
    directory = comm.bcast(str(tmp_path / "ckpt"), root=0)
    out_ref, out_run = comm.bcast((str(tmp_path / "ref"), str(tmp_path / "run")), root=0)
    problem, solver = _model()
    writer = ResultWriter(out_ref, comm, u=problem.u, interface=problem.interface)
    reference = []
    for inc in load_path(problem, solver, PROGRAM.times, verbose=False):
        writer.write(inc)
        reference.append(_record(problem, inc))
    solver.destroy()
    assert reference[-1]["D"] > 0.0                      # the cycle slipped: history matters

    problem, solver = _model()
    writer = ResultWriter(out_run, comm, u=problem.u, interface=problem.interface)
    for inc in load_path(problem, solver, PROGRAM.times, verbose=False, checkpoint=directory,
                         outputs=[writer]):
        writer.write(inc)
        if inc.step == 7:
            break        # the run stops after writing step 7, before its checkpoint
    solver.destroy()

    problem, solver = _model()
    writer = ResultWriter(out_run, comm, u=problem.u, interface=problem.interface, resume=True)
    resumed = []
    for inc in load_path(problem, solver, PROGRAM.times, verbose=False, resume=directory,
                         outputs=[writer]):
        writer.write(inc)
        resumed.append(_record(problem, inc))
    solver.destroy()
    assert [r["step"] for r in resumed] == list(range(7, len(reference) + 1))
    assert [r["lam"] for r in resumed] == [r["lam"] for r in reference[6:]]
    scale = max(np.abs(r["u"]).max() for r in reference)
    for got, ref in zip(resumed, reference[6:]):
        np.testing.assert_allclose(got["u"], ref["u"], rtol=0, atol=1e-12 * scale)
        assert got["D"] == pytest.approx(ref["D"], rel=1e-12, abs=1e-15)
        np.testing.assert_allclose(got["F"], ref["F"], rtol=1e-12, atol=1e-12 * abs(ref["F"][2]))

    # the output continues: every increment once, equal to the uninterrupted run's files
    if comm.rank == 0:
        import os

        run_rows, ref_rows = _csv(f"{out_run}/history.csv"), _csv(f"{out_ref}/history.csv")
        assert [r["step"] for r in run_rows] == list(range(1, len(reference) + 1))
        for got, ref in zip(run_rows, ref_rows):
            for key in ("load_factor", "dissipation_Nmm", "contact_fz_N", "contact_fx_N"):
                assert got[key] == pytest.approx(ref[key], rel=1e-9, abs=1e-12), key
        t_run, u_run = _xdmf_steps(f"{out_run}/displacement.xdmf")
        t_ref, u_ref = _xdmf_steps(f"{out_ref}/displacement.xdmf")
        assert t_run == t_ref and len(t_ref) == len(reference)
        for t in t_ref:
            np.testing.assert_allclose(u_run[t], u_ref[t], rtol=0, atol=1e-12 * scale)
        got, ref = (read_interface_results(f"{d}/interface.xdmf") for d in (out_run, out_ref))
        np.testing.assert_array_equal(got.times, ref.times)
        for name in ("pressure_MPa", "dissipation_N_per_mm"):
            for k in (6, -1):
                np.testing.assert_allclose(got.field(name, k), ref.field(name, k),
                                           rtol=1e-9, atol=1e-12 * np.abs(ref.field(name)).max())
        assert not [f for f in os.listdir(out_run) if f.endswith(".damaged")]
    comm.Barrier()


def test_resume_refuses_another_problem(tmp_path):
    directory = MPI.COMM_WORLD.bcast(str(tmp_path / "ckpt"), root=0)
    problem, solver = _model()
    for inc in load_path(problem, solver, PROGRAM.times[:2], verbose=False,
                         checkpoint=directory):
        pass
    solver.destroy()
    other, solver = _model(mesh_size=0.35)
    with pytest.raises(CheckpointError, match="written by another problem .*(num_dofs|dof_checksum)"):
        next(load_path(other, solver, PROGRAM.times[:2], resume=directory))
    solver.destroy()
    problem, solver = _model()
    with pytest.raises(CheckpointError, match=r"load factors given \(3\) differ from those of "
                       r"the checkpointed run \(2\)"):
        next(load_path(problem, solver, PROGRAM.times[:3], resume=directory))
    empty = MPI.COMM_WORLD.bcast(str(tmp_path / "none"), root=0)
    with pytest.raises(CheckpointError, match="holds no checkpoint"):
        next(load_path(problem, solver, PROGRAM.times[:2], resume=empty))
    solver.destroy()


def test_resume_refuses_another_partition(tmp_path, monkeypatch):
    """A checkpoint bound to its partition (no partition-independent node keys: simulated by
    a problem without them) refuses a rank holding other DOFs than when it was written (the
    global checksum cannot see it), naming the rank. Simulated by shifting the last rank's
    local checksum."""
    from rough_contact.fem.problem import ContactProblem
    from rough_contact.solver import checkpoint as ck

    comm = MPI.COMM_WORLD
    monkeypatch.setattr(ContactProblem, "owned_node_keys", lambda self: None)
    directory = comm.bcast(str(tmp_path / "ckpt"), root=0)
    problem, solver = _model()
    for inc in load_path(problem, solver, PROGRAM.times[:2], verbose=False,
                         checkpoint=directory):
        pass
    solver.destroy()
    real = ck._local_checksum

    def shifted(p):
        c = real(p)
        return c + (comm.rank == comm.size - 1) * np.array([0.0, 1.0, 0.0])

    monkeypatch.setattr(ck, "_local_checksum", shifted)
    problem, solver = _model()
    with pytest.raises(CheckpointError, match=rf"partitioned differently .*rank\(s\) "
                       rf"\[{comm.size - 1}\]"):
        next(load_path(problem, solver, PROGRAM.times[:2], resume=directory))
    solver.destroy()


def test_resume_refuses_another_law_or_program_naming_what_differs(tmp_path):
    """Issue 24: a checkpoint of friction case (b) resumed with case (a) (another friction law of
    the same class) was accepted and appended to the old history. Refused now, naming the
    parameter and both values as written (Fig 18: case b mu_macro 0.5, mu_o ratio 0.5; case a
    0.2 and 1.0). A load program with another cyclic amplitude (same pseudo-times) is refused
    too, naming the channel and the first pseudo-time where the scales differ (1.125: a quarter
    of the way up the first cycle's ramp, a/2 = 0.5 vs 0.25)."""
    directory = MPI.COMM_WORLD.bcast(str(tmp_path / "ckpt"), root=0)
    problem, solver = _model()
    for inc in load_path(problem, solver, PROGRAM.times[:3], verbose=False,
                         checkpoint=directory):
        pass
    solver.destroy()
    other, solver = _model(case="a")
    with pytest.raises(CheckpointError) as err:
        next(load_path(other, solver, PROGRAM.times[:3], resume=directory))
    msg = str(err.value)
    assert "interface law differs" in msg
    assert "friction.mu_macro[0]: 0.5 in the checkpoint, 0.2 now" in msg
    assert "friction.mu_initial_ratio[1]: 0.5 in the checkpoint, 1.0 now" in msg
    assert "pairing differs" not in msg and "load program" not in msg
    solver.destroy()
    half = preload_then_cyclic(preload_steps=2, cycles=1, steps_per_cycle=8, amplitude=0.5)
    assert half.times[:3] == PROGRAM.times[:3]
    other, solver = _model(program=half)
    with pytest.raises(CheckpointError, match=r"load program differs: cyclic\.t=1\.125: 0\.5 "
                       r"in the checkpoint, 0\.25 now"):
        next(load_path(other, solver, PROGRAM.times[:3], resume=directory))
    solver.destroy()
    problem, solver = _model()                  # the same problem resumes
    assert [inc.step for inc in load_path(problem, solver, PROGRAM.times[:3], verbose=False,
                                          resume=directory)] == []
    solver.destroy()


def test_resumed_displacement_output_on_another_node_layout(tmp_path, monkeypatch):
    """A resumed run whose mesh lists its nodes in another order (another partition: simulated
    by giving the resumed writer another layout digest) writes its steps against a mesh grid of
    its own in displacement.xdmf, so every step reads back with the values of the uninterrupted
    run (same mesh here, so the arrays compare directly); a second resume on that layout reuses
    the grid."""
    from rough_contact.io import results

    comm = MPI.COMM_WORLD
    directory = comm.bcast(str(tmp_path / "ckpt"), root=0)
    out_ref, out_run = comm.bcast((str(tmp_path / "ref"), str(tmp_path / "run")), root=0)
    times = PROGRAM.times[:6]
    problem, solver = _model()
    writer = ResultWriter(out_ref, comm, u=problem.u)
    for inc in load_path(problem, solver, times, verbose=False):
        writer.write(inc)
    solver.destroy()
    problem, solver = _model()
    writer = ResultWriter(out_run, comm, u=problem.u)
    for inc in load_path(problem, solver, times, verbose=False, checkpoint=directory,
                         outputs=[writer], max_steps=3):
        writer.write(inc)
    solver.destroy()
    monkeypatch.setattr(results.ResultWriter, "_layout", lambda self: "f" * 64)
    for stop in (4, None):                # resumed twice on the "other" layout
        problem, solver = _model()
        writer = ResultWriter(out_run, comm, u=problem.u, resume=True)
        for inc in load_path(problem, solver, times, verbose=False, checkpoint=directory,
                             resume=directory, outputs=[writer], max_steps=stop and 1):
            writer.write(inc)
        solver.destroy()
    if comm.rank == 0:
        from rough_contact.io.files import parse_xdmf

        t_run, u_run = _xdmf_steps(f"{out_run}/displacement.xdmf")
        t_ref, u_ref = _xdmf_steps(f"{out_ref}/displacement.xdmf")
        assert t_run == t_ref and len(t_ref) == 6
        for t in t_ref:
            np.testing.assert_allclose(u_run[t], u_ref[t], rtol=0,
                                       atol=1e-12 * np.abs(u_ref[t_ref[-1]]).max())
        text = open(f"{out_run}/displacement.xdmf").read()
        root = parse_xdmf(f"{out_run}/displacement.xdmf")
        names = [g.get("Name") for g in root.find("Domain").findall("Grid")]
        assert names == ["mesh", "displacement", "mesh_ffffffffffff"]
        assert text.count("@Name='mesh_ffffffffffff'") == 3      # steps 4, 5, 6
    comm.Barrier()
