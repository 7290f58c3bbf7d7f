"""The flat punch with the statistical and the boundary-element normal law on the same surface.

The quarter punch of :mod:`rough_contact.scenes.flat_punch` (E = 200 GPa, nu = 0.25, friction
case (b)) is loaded twice on the same rough surface, once with the statistical elastic law
(asperity sums) and once with the BEM law of that surface (:mod:`rough_contact.micro.bem`: exact
elastic contact of Gaussian realisations of the surface's spectrum). Everything else is
identical, so the differences are the effect of the normal law: approach of the loaded patch,
interface closure, int k dA, real contact area, dissipation. The tangential stiffness is the
friction case's kT = c kN (the paper's c = 0.7) unless ``kt="bem"``: then both runs take the
ratios kT/kN the BEM computes for the surface in full stick (``BEMLaw.tangential``; Mindlin's
2(1 - nu)/(2 - nu) for an isotropic surface, different along and across the grain of an
anisotropic one), so the comparison still isolates the normal law. The default load is a bolted-joint
level 50 kN (nominal 125 MPa), where the contact pressures lie inside the BEM table
(``docs/bem.md``). Library code (no petsc4py.init, no sys.argv). Units: mm, N, MPa.
"""

from __future__ import annotations

import os
from dataclasses import astuple, dataclass, fields

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.boundary import SurfaceMean
from rough_contact.references import effective_modulus
from rough_contact.scenes import flat_punch as punch
from rough_contact.solver.loading import load_path, load_unload_factors

__all__ = ["LawIncrement", "LawComparison", "build_laws", "run_with_law", "run"]


@dataclass(frozen=True)
class LawIncrement:
    """One converged increment of the punch with one normal law; whole-punch figures
    (identical on every rank).

    Attributes:
        force: applied force [N].
        approach: mean downward displacement of the loaded patch [mm].
        closure: mean compression of the rough layer, -(mean interface gap) [mm].
        k_int: int dp/dh dA over the interface [N/mm].
        real_area: real contact area [mm^2].
        dissipation: interface dissipation [N mm].
        below, beyond: interface points below / beyond the normal law's table.
        p_max: largest interface pressure [MPa].
        force_error: |Fz_contact + Fz_applied| / |Fz_applied| [-].
        n_points: global number of interface points.
    """

    force: float
    approach: float
    closure: float
    k_int: float
    real_area: float
    dissipation: float
    below: int
    beyond: int
    p_max: float
    force_error: float
    n_points: int


@dataclass(frozen=True)
class LawComparison:
    """Result of :func:`run`: the increments with each normal law on the same surface.

    Attributes:
        statistical: increments with the statistical elastic law (:class:`LawIncrement`).
        bem: increments with the BEM law.
        num_dofs: global number of DOFs (same mesh for both).
        kt_over_kn: (kTx/kN, kTy/kN) used by both runs [-].
        kt_source: "case (c)" for the friction case's ratios, "bem" for the BEM's.
    """

    statistical: list
    bem: list
    num_dofs: int
    kt_over_kn: tuple = (0.7, 0.7)
    kt_source: str = "case"

    def items(self):
        """(law name, increments) pairs: ("statistical", ...), ("BEM", ...)."""
        return (("statistical", self.statistical), ("BEM", self.bem))


# ## The two normal laws (built on rank 0, copied to the others)
def build_laws(comm, surface, realisations, ppw, small, backend=None, tangential=False):
    """{"statistical": NormalLaw, "BEM": NormalLaw} and the BEMLaw info (with
    ``info["kt_over_kn"]``, the BEM's stick ratios, when ``tangential``). Collective."""
    laws = info = None
    if comm.rank == 0:
        import warnings

        from rough_contact.micro import bem
        from rough_contact.interface.normal import NormalLaw
        from rough_contact.surface.spectrum import example_surfaces

        m, shape = example_surfaces()[surface]
        E_star = effective_modulus(punch.E, punch.NU, punch.E, punch.NU)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)    # isotropic: model-validity warning
            stat = NormalLaw.elastic(m, E_star)
            b = bem.bem_law_from_moments(
                m, E_star=E_star, nu=punch.NU, n_realisations=2 if small else realisations,
                pixels_per_wavelength=3.0 if small else ppw, n_pressures=6 if small else 14,
                area_range=(0.002, 0.45), tangential=tangential, backend=backend,
                tangential_realisations=4)
        laws = {"statistical": stat, "BEM": b.normal}
        info = dict(b.info)
        if tangential:
            info["kt_over_kn"] = b.tangential().kt_over_kn
    return comm.bcast(laws, root=0), comm.bcast(info, root=0)


# ## One run of the punch with a given normal law
def run_with_law(comm, normal, force, steps, case, mesh_size, contact_size, order, verbose,
                 kt_over_kn=None):
    """Load to ``force`` in ``steps`` increments; returns (list of :class:`LawIncrement`,
    number of DOFs), identical on every rank. Collective. ``kt_over_kn`` replaces the friction
    case's tangential ratios."""
    m = punch.build(comm, mesh_size, contact_size, order, case=case, normal_law="elastic",
                    steps=steps, normal=normal, total_force=float(force), kt_over_kn=kt_over_kn)
    scene, problem, solver, interface, law = m.scene, m.problem, m.solver, m.interface, m.law
    uz_load = SurfaceMean(problem.u, scene.facet_tags, scene.tag("load"), 2)
    rows = []
    for inc in load_path(problem, solver, load_unload_factors(steps, 0), verbose=verbose):
        pf = interface.point_fields()
        h = law.h0 + pf.gap
        _, k, _ = law.normal.evaluate(h)
        w = pf.weight
        glob = lambda v: comm.allreduce(float(v), op=MPI.SUM)  # noqa: E731
        area = glob(w.sum())
        rows.append(LawIncrement(
            force=-inc.applied_force[2] * 4.0,                 # full punch [N]
            approach=-uz_load.integral() / uz_load.area,
            closure=-glob(np.dot(pf.gap, w)) / area,          # mean compression of the layer
            k_int=4.0 * glob(np.dot(k, w)),                   # full punch [N/mm]
            real_area=4.0 * glob(np.dot(pf.area_fraction, w)),
            dissipation=4.0 * interface.dissipation(),
            below=comm.allreduce(law.normal.count_below_validity(h), op=MPI.SUM),
            beyond=comm.allreduce(int(np.count_nonzero(h > law.normal.h_table_end)),
                                  op=MPI.SUM),
            p_max=comm.allreduce(float(pf.pressure.max(initial=0.0)), op=MPI.MAX),
            force_error=abs(inc.contact_force[2] + inc.applied_force[2])
            / abs(inc.applied_force[2]),
            n_points=interface.n_points_global))
    solver.destroy()
    return rows, problem.num_dofs


def run(surface="anisotropic", force=50e3, steps=8, case="b", mesh_size=20.0, contact_size=2.0,
         order=2, realisations=8, ppw=8.0, small=False, backend=None, outdir=None,
         comm=MPI.COMM_WORLD, verbose=True, kt="case"):
    """Run both laws; print the comparison; return a :class:`LawComparison`. Collective.

    ``kt``: "case" (the friction case's kT/kN, the paper's 0.7) or "bem" (the BEM's stick
    ratios of this surface, in both runs; computing them about doubles the BEM build)."""
    if kt not in ("case", "bem"):
        raise ValueError(f"kt = {kt!r} is invalid; valid: 'case' (the friction case's kT/kN) "
                         "or 'bem' (the BEM's stick ratios)")
    t0 = MPI.Wtime()
    if small:
        mesh_size, contact_size, order, steps = 40.0, 5.0, 1, 2
    laws, info = build_laws(comm, surface, realisations, ppw, small, backend,
                            tangential=(kt == "bem"))
    kt_ratio = tuple(info["kt_over_kn"]) if kt == "bem" else tuple(punch.FRICTION_CASES[case]["kt"])
    PETSc.Sys.Print(f"Normal laws of the '{surface}' surface: statistical elastic "
                    f"({laws['statistical'].n_intervals} intervals) and BEM ({info['backend']}, "
                    f"{info['realisations']} realisations of {info['grid'][0]}x{info['grid'][1]} "
                    f"px, A/A0 {info['area_range'][0]:.3g}-{info['area_range'][1]:.3g}, "
                    f"p {info['pressure_range'][0]:.3g}-{info['pressure_range'][1]:.3g} MPa); "
                    f"built in {MPI.Wtime() - t0:.1f} s", comm=comm)
    from rough_contact.micro.bem import mindlin_ratio

    PETSc.Sys.Print(f"tangential stiffness kT/kN = ({kt_ratio[0]:.3f}, {kt_ratio[1]:.3f}) in "
                    "both runs, " + ("computed by the BEM in full stick" if kt == "bem" else
                                     f"friction case ({case}); --kt bem takes the BEM's")
                    + f" (Mindlin's circular contact: {mindlin_ratio(punch.NU):.3f})", comm=comm)
    out = {}
    for name, normal in laws.items():
        rows, ndofs = run_with_law(comm, normal, force, steps, case, mesh_size, contact_size,
                                   order, verbose=False, kt_over_kn=kt_ratio)
        out[name] = rows
        PETSc.Sys.Print(f"  {name:12s}: {ndofs} DOFs, {rows[-1].n_points} interface points, "
                        f"{len(rows)} increments, max force error "
                        f"{max(r.force_error for r in rows):.1e}", comm=comm)
    s, b = out["statistical"], out["BEM"]
    PETSc.Sys.Print(f"\nFlat punch, '{surface}' surface, friction case ({case}), loading to "
                    f"{force:g} N in {steps} increments (seated at the first); full-punch "
                    "figures\n", comm=comm)
    hdr = (f"{'F [N]':>9s} | {'approach [um]':>21s} | {'closure [um]':>21s} | "
           f"{'int k dA [N/mm]':>23s} | {'real area [mm2]':>19s}")
    PETSc.Sys.Print(hdr + "\n" + f"{'':9s} | {'stat':>6s} {'BEM':>6s} {'diff':>7s} | "
                    f"{'stat':>6s} {'BEM':>6s} {'diff':>7s} | {'stat':>7s} {'BEM':>7s} "
                    f"{'diff':>7s} | {'stat':>5s} {'BEM':>5s} {'diff':>7s}", comm=comm)
    rel = lambda x, y: (y - x) / x if x else float("nan")  # noqa: E731
    for rs, rb in zip(s, b):
        PETSc.Sys.Print(
            f"{rs.force:9.4g} | {rs.approach * 1e3:6.3f} {rb.approach * 1e3:6.3f} "
            f"{rel(rs.approach, rb.approach):+7.1%} | {rs.closure * 1e3:6.3f} "
            f"{rb.closure * 1e3:6.3f} {rel(rs.closure, rb.closure):+7.1%} | "
            f"{rs.k_int:7.3g} {rb.k_int:7.3g} {rel(rs.k_int, rb.k_int):+7.1%} | "
            f"{rs.real_area:5.3g} {rb.real_area:5.3g} "
            f"{rel(rs.real_area, rb.real_area):+7.1%}", comm=comm)
    # secant stiffness of the whole punch over the last increment
    ks = [(r[-1].force - r[-2].force) / (r[-1].approach - r[-2].approach) for r in (s, b)]
    PETSc.Sys.Print(
        f"\nsecant punch stiffness dF/d(approach), last increment: statistical {ks[0]:.4g} N/mm, "
        f"BEM {ks[1]:.4g} N/mm ({rel(ks[0], ks[1]):+.1%})\n"
        f"dissipation D at {force:g} N: statistical {s[-1].dissipation:.4g} N mm, BEM "
        f"{b[-1].dissipation:.4g} N mm ({rel(s[-1].dissipation, b[-1].dissipation):+.1%})"
        f"\nlargest contact pressure: statistical {s[-1].p_max:.4g} MPa, BEM "
        f"{b[-1].p_max:.4g} MPa; points below the table (continuation) / beyond it (taper) "
        f"at the peak: statistical {s[-1].below}/{s[-1].beyond}, BEM "
        f"{b[-1].below}/{b[-1].beyond} of {s[-1].n_points}\n"
        f"wall time {MPI.Wtime() - t0:.1f} s", comm=comm)
    if outdir and comm.rank == 0:
        import csv

        os.makedirs(outdir, exist_ok=True)
        with open(os.path.join(outdir, "history.csv"), "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["law"] + [f.name for f in fields(LawIncrement)])
            for name, rows in out.items():
                for r in rows:
                    w.writerow([name] + list(astuple(r)))
    for rows in out.values():
        assert max(r.force_error for r in rows) < 1e-6, "force balance violated"
    return LawComparison(statistical=out["statistical"], bem=out["BEM"], num_dofs=ndofs,
                         kt_over_kn=kt_ratio, kt_source=kt)


