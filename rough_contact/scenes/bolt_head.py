"""A cylinder (a bolt head, a pin) standing on a block, meshed separately, under the rough law.

The scene a user copies for parts meshed independently (``cylinder_on_block``: the cylinder's
mesh finer than the block's, no common surface mesh), paired by segment-to-segment (mortar)
integration: the cylinder's base is the first contact surface (it lies within the block's top).
The interface is the paper's rough surface (section 9.2 spectral moments, elastic asperities)
with orthotropic slip-hardening friction (case (b): mu from 0.25 to 0.5 with accumulated slip,
grain along x). The block is clamped at its bottom. The cylinder's top carries the preload P
(channel ``preload``: ramped in ``preload_steps`` increments, then held) and is then moved
tangentially by u_x = s (channel ``shear``: 0 during the preload, then ramped to ``slide``
in ``shear_steps`` increments; u_y, u_z free). The cylinder is held only by the interface
(a seating spring helps the first Newton steps, see ``ContactProblem(seating_tag=)``).

Checked at every converged increment: the interface force on the cylinder balances the
preload in z and the reaction of the prescribed top displacement in x, to 1e-8 of P.

Units: mm, N, MPa (the slide given in um at the API).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.compat import vector_space
from rough_contact.fem.problem import Material
from rough_contact.scenes import flat_punch
from rough_contact.scenes.defaults import GRAIN_X, quadrature_degree
from rough_contact.scenes.setup import clamped_pair, preload_then_drive
from rough_contact.scenes.meshes.blocks import cylinder_on_block
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import LoadProgram
from rough_contact.solver.snes import SNESSolver
from rough_contact.validation import check_scalar

__all__ = ["BoltIncrement", "BoltHeadRun", "program", "run"]


@dataclass(frozen=True)
class BoltIncrement:
    """One converged increment of :func:`run`.

    Attributes:
        t: pseudo-time (preload over [0, 1], slide over [1, 2]).
        u_x: prescribed slide of the cylinder's top [mm].
        F_z: normal force of the block on the cylinder (up) [N].
        F_x: friction force resisting the slide [N].
        real_area: real contact area [mm^2].
        dissipation: cumulative interface dissipation [N mm].
        slip_fraction: slipping nominal area / nominal area [-].
        balance: force-balance defect / P [-].
        newton: Newton iterations spent so far.
    """

    t: float
    u_x: float
    F_z: float
    F_x: float
    real_area: float
    dissipation: float
    slip_fraction: float
    balance: float
    newton: int


@dataclass(frozen=True)
class BoltHeadRun:
    """Result of :func:`run` (identical on every rank).

    Attributes:
        P: preload [N].
        dofs: global number of DOFs.
        points: global number of interface points.
        pairing: the pairing used ("mortar", "projection").
        rows: the increments (:class:`BoltIncrement`).
    """

    P: float
    dofs: int
    points: int
    pairing: str
    rows: list


def program(preload_steps: int, shear_steps: int) -> LoadProgram:
    """``preload`` ramps to 1 over t in [0, 1] and holds; ``shear`` ramps 0 -> 1 over [1, 2]."""
    def ramp(t):
        return min(max(t, 0.0), 1.0)

    times = [(i + 1) / preload_steps for i in range(preload_steps)]
    times += [1.0 + (i + 1) / shear_steps for i in range(shear_steps)]
    return LoadProgram({"preload": ramp, "shear": lambda t: ramp(t - 1.0)}, times)


def run(pressure=10.0, slide_um=2.0, radius=5.0, height=5.0, size_cylinder=1.0,
        size_block=1.6, order=1, pairing="mortar", preload_steps=2, shear_steps=4,
        comm=MPI.COMM_WORLD, verbose=True) -> BoltHeadRun:
    """Preload the cylinder to ``pressure`` [MPa] nominal on its base, then slide its top by
    ``slide_um`` [um]. Collective; returns the per-increment table (:class:`BoltHeadRun`,
    identical on every rank).

    Raises:
        ValueError: bad sizes or loads (named with their value and range).
        AssertionError: the force balance is violated by more than 1e-8 of P at an increment.
    """
    check_scalar("pressure", pressure, lo=0.0, unit="MPa")
    slide = check_scalar("slide", slide_um, lo=0.0, lo_open=False, unit="um") * 1e-3
    for name, n in (("preload_steps", preload_steps), ("shear_steps", shear_steps)):
        if check_scalar(name, n, lo=1, lo_open=False) != int(n):
            raise ValueError(f"{name} = {n!r} is invalid: it must be an integer >= 1")
    scene = cylinder_on_block(radius=radius, height=height, size_cylinder=size_cylinder,
                              size_block=size_block, order=order, comm=comm)
    V = vector_space(scene.mesh, order)
    P = pressure * np.pi * radius**2
    law, _ = flat_punch.make_law(comm, case="b", normal_law="elastic",
                                 seating_pressure=pressure / preload_steps)
    clamp, interface = clamped_pair(scene, V, law, grain_direction=GRAIN_X,
                                    quadrature_degree=quadrature_degree(order), pairing=pairing)
    top = scene.tag("cylinder_top")
    prog = program(preload_steps, shear_steps)
    problem = preload_then_drive(scene, V, Material(flat_punch.E, flat_punch.NU), clamp,
                                 interface, top, P, slide, "shear", prog.channels)
    solver = SNESSolver(problem, prefix="bolt_")
    rows = []
    if verbose:
        PETSc.Sys.Print(f"{scene.mesh.topology.index_map(3).size_global} cells, "
                        f"{problem.num_dofs} DOFs, pairing {interface.pairing_used}, "
                        f"{interface.n_points_global} interface points, P = {P:.1f} N")
        PETSc.Sys.Print("N = normal force of the block on the cylinder, Q = friction force "
                        "resisting the slide")
        PETSc.Sys.Print(f"{'t':>5} {'u_x um':>7} {'N [N]':>9} {'Q [N]':>8} {'Q/N':>7} "
                        f"{'slip %':>6} {'A_r mm2':>8} {'D N mm':>9} {'balance':>8} {'Newton':>6}")
    for inc in load_path(problem, solver, prog.times, verbose=False):
        F = inc.contact_force                                 # on the cylinder
        Rx = problem.reaction(top)[0]                         # on the cylinder's top
        applied_z = -P * problem.scales["preload"]
        balance = max(abs(F[2] + applied_z), abs(F[0] + Rx)) / P
        s = interface.summary()
        # F_z: normal force on the cylinder (up); F_x: friction force resisting the slide
        row = BoltIncrement(t=inc.load_factor, u_x=problem.scales["shear"] * slide, F_z=F[2],
                            F_x=-F[0], real_area=inc.real_area, dissipation=inc.dissipation,
                            slip_fraction=s.slipping_area / s.nominal_area, balance=balance,
                            newton=inc.newton_total)
        rows.append(row)
        if verbose:
            PETSc.Sys.Print(f"{row.t:5.2f} {1e3 * row.u_x:7.3f} {row.F_z:9.2f} "
                            f"{row.F_x:8.2f} {row.F_x / row.F_z:7.3f} "
                            f"{100 * row.slip_fraction:6.1f} {row.real_area:8.4f} "
                            f"{row.dissipation:9.3e} {balance:8.1e} {row.newton:6d}")
        assert balance <= 1e-8, f"force balance violated at t = {inc.load_factor}: {balance:.3e}"
    solver.destroy()
    return BoltHeadRun(P=P, dofs=problem.num_dofs, points=interface.summary().n_points,
                       pairing=interface.pairing_used, rows=rows)
