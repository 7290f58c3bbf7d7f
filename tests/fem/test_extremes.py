"""Stability of the flat punch (paper section 9.2) at the extremes of the parameter ranges.

Every case runs the quarter punch on one coarse P1 mesh (built once per module) through
``load_unload_factors(4, 2)`` with one parameter pushed to an extreme: the load (1e-3x and
100x the paper's 1000 N), the friction coefficient, the slip-hardening rate, kT/kN, the
roughness m00, the plasticity index psi, and a nearly isotropic surface. A run must either

* converge, with finite and physically signed results: pressure >= 0 at every interface point,
  dissipation >= 0 (total and at every point), normal force balance to 1e-6 at every
  increment; or
* stop cleanly with a :class:`~rough_contact.solver.loading.LoadStepError` naming the load
  factor it could not reach, with every converged increment written to ``history.csv``.

In both cases the CSV must exist, parse and hold one row per converged increment.

Units: mm, N, MPa. Serial and ``mpirun -n 2``.

The table of docs/extremes.md is printed by ``test_summary_table`` (run with ``-s``) or by::

    OPENBLAS_NUM_THREADS=1 .venv/bin/python tests/fem/test_extremes.py [case names] [--probes]
"""

from __future__ import annotations

import csv
import dataclasses
import logging
import os
import sys
import tempfile
import time
import warnings

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.scenes import flat_punch as demo  # noqa: E402

from petsc4py import PETSc  # noqa: E402

from rough_contact.interface.contract import ConvergenceError  # noqa: E402
from rough_contact.io import ResultWriter  # noqa: E402
from rough_contact.solver.loading import LoadStepError, load_path, load_unload_factors  # noqa: E402

# Coarse scene: ~1 s per Newton solve sequence on one core.
MESH = dict(mesh_size=20.0, contact_size=2.5, order=1, load_half_width=2.5)
N_LOAD, N_UNLOAD = 4, 2
FACTORS = load_unload_factors(N_LOAD, N_UNLOAD)
NORMAL_RTOL = 1e-2  # loose normal-law tables: fast to build, still smooth and monotone
MIN_INCREMENT = 1e-3  # smallest cutback increment (of the load factor)
SNES_MAX_IT = 30
FORCE_TOL = 1e-6

# The strongly anisotropic model is built for m04/m40 >> 1 (paper: 100 and 6561).
ISOTROPIC_MOMENTS_UM = dict(m00=0.625, m20=8e-4, m02=8e-4 * 1.05, m40=1.04e-4,
                            m04=1.04e-4 * 1.05)


def scaled_moments(m00_um2: float) -> dict:
    """The paper's surface with every height scaled so that m00 = ``m00_um2`` [um^2].

    Scaling heights by c multiplies all five moments by c^2: the wavelengths (and with them the
    bandwidths alpha1, alpha2, which must stay > 2 for a valid surface) are unchanged. Scaling
    m00 alone would give alpha < 2 for m00 = 1e-4 um^2 (an invalid covariance, ValueError).
    """
    c2 = m00_um2 / demo.MOMENTS_UM["m00"]
    return {k: v * c2 for k, v in demo.MOMENTS_UM.items()}


@dataclasses.dataclass(frozen=True)
class Case:
    """One extreme: deviations from the paper's case (b) with the elastic normal law.

    Attributes:
        name: label in the table.
        load_scale: total force / 1000 N [-].
        mu: macroscopic friction coefficient mu_m (both axes) [-].
        hardening: slip-hardening rate n (both axes) [1/mm].
        kt: kT/kN (both axes) [-].
        moments: spectral moments in um units.
        psi: plasticity index (elasto-plastic normal law) or None for the elastic law [-].
    """

    name: str
    load_scale: float = 1.0
    mu: float = 0.5
    hardening: float = demo.HARDENING[0]
    kt: float = 0.7
    moments: tuple = tuple(demo.MOMENTS_UM.items())
    psi: float | None = None
    forced_failure: bool = False


class FailingLaw:
    """Wraps an interface law; once ``p_limit`` is set, a pressure above it raises a
    ConvergenceError (the failure type that makes the load stepping cut back).

    Used to drive the load path deterministically into its clean stop (cutback down to the
    minimum increment, then LoadStepError), independently of round-off.
    """

    def __init__(self, law):
        self.law = law
        self.p_limit = np.inf

    def initial_state(self, n_pts):
        return self.law.initial_state(n_pts)

    def evaluate(self, jump, committed):
        res = self.law.evaluate(jump, committed)
        p_max = float(np.max(-res.traction[:, 0], initial=0.0))
        if p_max > self.p_limit:
            raise ConvergenceError(f"forced failure: pressure {p_max:.4g} MPa above the limit "
                             f"{self.p_limit:.4g} MPa")
        return res

    def __getattr__(self, name):
        return getattr(self.law, name)


CASES = [
    Case("paper (b), elastic law"),
    Case("load x 1e-3 (1 N)", load_scale=1e-3),
    Case("load x 1e2 (1e5 N)", load_scale=1e2),
    Case("mu = 1e-6", mu=1e-6),
    Case("mu = 5", mu=5.0),
    Case("n = 0 /mm", hardening=0.0),
    Case("n = 1e6 /mm", hardening=1e6),
    Case("kT/kN = 1e-4", kt=1e-4),
    Case("kT/kN = 1e2", kt=1e2),
    Case("m00 = 1e-4 um^2 (smooth)", moments=tuple(scaled_moments(1e-4).items())),
    Case("m00 = 10 um^2 (rough)", moments=tuple(scaled_moments(10.0).items())),
    Case("psi = 0.35 (paper, elasto-plastic)", psi=0.35),
    Case("psi = 0.05", psi=0.05),
    Case("psi = 5", psi=5.0),
    Case("m04/m40 = 1.05 (nearly isotropic)", moments=tuple(ISOTROPIC_MOMENTS_UM.items())),
    # beyond the requested ranges: where the limits are
    Case("beyond: load x 1e-6 (1 mN)", load_scale=1e-6),
    Case("beyond: load x 1e4 (1e7 N)", load_scale=1e4),
    Case("beyond: kT/kN = 1e4", kt=1e4),
    # the clean stop, forced: after step 2 any pressure 5 % above the current maximum fails
    Case("forced law failure after step 2", forced_failure=True),
]


# Further probes (runner only, ``--probes``; not part of the pytest module to keep it short)
PROBES = [
    Case("probe: mu = 100", mu=100.0),
    Case("probe: kT/kN = 1e-8", kt=1e-8),
    Case("probe: m00 = 1e-6 um^2", moments=tuple(scaled_moments(1e-6).items())),
    Case("probe: m00 = 1e3 um^2", moments=tuple(scaled_moments(1e3).items())),
    Case("probe: load x 1e3 (1e6 N)", load_scale=1e3),
]


@dataclasses.dataclass
class Outcome:
    """What one run gave (identical on every rank)."""

    case: Case
    converged: bool
    error: str = ""
    failed_factor: float = float("nan")
    last_converged: float = 0.0
    increments: list = dataclasses.field(default_factory=list)
    cutbacks: int = 0
    failed_solves: int = 0
    max_force_error: float = float("nan")
    dissipation: float = float("nan")
    min_pressure: float = float("nan")
    min_point_dissipation: float = float("nan")  # accumulated t_T . du_p per area [N/mm]
    max_point_dissipation: float = float("nan")
    max_pressure: float = float("nan")
    real_area_fraction: float = float("nan")  # max over increments of A_real / A_patch
    wall_time: float = 0.0
    dissipation_bound: float = float("nan")
    max_below_validity: int = 0
    n_points: int = 0
    csv_rows: list = dataclasses.field(default_factory=list)

    @property
    def newton(self):
        its = [i.iterations for i in self.increments]
        return (max(its), float(np.median(its))) if its else (0, float("nan"))


# ---------------------------------------------------------------------------------- scene
class Scene:
    """The coarse quarter punch, its space, conditions and loads; shared by every case."""

    def __init__(self, comm):
        self.comm = comm
        self.punch = demo.quarter_punch(comm, **MESH)
        self.scene = sc = self.punch.scene
        self.contact_area = sc.dimensions["half_width"] ** 2
        self._normal_cache: dict = {}
        self.n_runs = 0

    def normal_law(self, moments: tuple, psi):
        """Normal-law table (rank 0 builds, all get a copy); cached per (moments, psi)."""
        key = (moments, psi)
        if key not in self._normal_cache:
            normal, err = None, None
            if self.comm.rank == 0:
                from rough_contact.interface.normal import NormalLaw
                from rough_contact.surface import SpectralMoments

                try:
                    surface = SpectralMoments(**dict(moments), unit="um")
                    E_star = demo.effective_modulus(demo.E, demo.NU, demo.E, demo.NU)
                    if psi is None:
                        normal = NormalLaw.elastic(surface, E_star, rtol=NORMAL_RTOL)
                    else:
                        from rough_contact.micro.asperity import AsperityMaterial

                        mat = AsperityMaterial(E_star=E_star, nu=demo.NU,
                                               **dict(demo.PLASTIC, psi=psi))
                        normal = NormalLaw.elasto_plastic(surface, mat, rtol=NORMAL_RTOL)
                except ValueError as exc:
                    err = f"{type(exc).__name__}: {exc}"
            normal, err = self.comm.bcast((normal, err), root=0)
            if err:
                raise ValueError(err)
            self._normal_cache[key] = normal
        return self._normal_cache[key]

    def interface_law(self, case: Case, p_seat: float):
        """The interface law of ``case`` (pattern of rough_contact.scenes.flat_punch.make_law, case (b))."""
        from rough_contact.interface.friction import OrthotropicSlipHardening
        from rough_contact.interface.law import InterfaceLaw
        from rough_contact.interface.tangential import TangentialStiffness

        b = demo.FRICTION_CASES["b"]
        friction = OrthotropicSlipHardening(mu_macro=(case.mu, case.mu),
                                            mu_initial_ratio=b["mu_initial_ratio"],
                                            hardening=(case.hardening, case.hardening),
                                            potential_axes=b["nu"])
        law = InterfaceLaw(normal=self.normal_law(case.moments, case.psi),
                           tangential=TangentialStiffness((case.kt, case.kt)), friction=friction)
        law = law.with_seating(p_seat)
        return FailingLaw(law) if case.forced_failure else law

    def run(self, case: Case, outdir: str) -> Outcome:
        """Load/unload the punch with ``case``'s law; write history.csv in ``outdir``."""
        comm = self.comm
        t0 = time.perf_counter()
        quarter_force = demo.TOTAL_FORCE * case.load_scale / 4.0
        p_seat = quarter_force / N_LOAD / self.contact_area  # seat with the first increment
        law = self.interface_law(case, p_seat)
        # A fresh options prefix per run (the solver removes its defaults after use, so this
        # only keeps the runs' command-line options apart).
        self.n_runs += 1
        m = demo.build(comm, law=law, steps=N_LOAD, prefix=f"rcext{self.n_runs}_",
                       punch_scene=self.punch, total_force=demo.TOTAL_FORCE * case.load_scale,
                       solver_defaults={"snes_max_it": SNES_MAX_IT})
        interface, problem, solver = m.interface, m.problem, m.solver
        # count every Newton solve and its outcome (a failed one is followed by a cutback)
        attempts = []
        solve = solver.solve

        def counting_solve(*args, **kwargs):
            try:
                res = solve(*args, **kwargs)
            except Exception:
                attempts.append(False)
                raise
            attempts.append(bool(res.converged))
            return res

        solver.solve = counting_solve
        writer = ResultWriter(outdir, comm, u=None,
                              extra_columns=("force_error_rel",))
        out = Outcome(case=case, converged=False)
        min_p, min_d, max_p, max_d = np.inf, np.inf, 0.0, 0.0
        # Upper bound of the dissipation from |t_T| <= mu_m p (the hardening coefficient never
        # exceeds mu_m; the orthotropic limit ellipse lies inside the circle of radius
        # max(mu_mx, mu_my) p): per increment, int t_T . ds_p dA <= mu_m F_N max|ds_p| and
        # max|ds_p| <= max|s_p(new)| + max|s_p(old)|.
        bound, sp_old = 0.0, 0.0
        try:
            for inc in load_path(problem, solver, FACTORS, min_increment=MIN_INCREMENT,
                                 verbose=False, validity="ignore"):   # counted below
                err = abs(inc.contact_force[2] + inc.applied_force[2]) / abs(inc.applied_force[2])
                writer.write(inc, extra={"force_error_rel": err})
                out.increments.append(inc)
                pf = interface.point_fields()
                finite = bool(np.all(np.isfinite(pf.pressure)) and np.all(np.isfinite(pf.dissipation)))
                if not comm.allreduce(finite, op=MPI.LAND):
                    raise AssertionError(f"{case.name}: non-finite point fields at load factor "
                                         f"{inc.load_factor}")
                min_p = min(min_p, comm.allreduce(float(pf.pressure.min(initial=np.inf)), op=MPI.MIN))
                max_p = max(max_p, comm.allreduce(float(pf.pressure.max(initial=0.0)), op=MPI.MAX))
                min_d = min(min_d, comm.allreduce(float(pf.dissipation.min(initial=np.inf)),
                                                  op=MPI.MIN))
                max_d = max(max_d, comm.allreduce(float(pf.dissipation.max(initial=0.0)),
                                                  op=MPI.MAX))
                # points below the model's validity (A/A0 beyond the table: stiff continuation)
                n_below = law.normal.count_below_validity(law.h0 + pf.gap)
                n_below = comm.allreduce(n_below, op=MPI.SUM)
                assert inc.n_beyond_validity == n_below     # the load stepping's own count
                out.max_below_validity = max(out.max_below_validity, n_below)
                out.n_points = inc.n_points
                sp_new = interface.summary().max_plastic_slip
                bound += case.mu * abs(inc.contact_force[2]) * (sp_new + sp_old)
                sp_old = sp_new
                if case.forced_failure and inc.step == 2:
                    law.p_limit = 1.05 * max_p
            out.converged = True
        except LoadStepError as exc:
            out.error = str(exc)
            out.failed_factor = exc.load_factor
            out.last_converged = exc.last_converged
        out.failed_solves = sum(1 for a in attempts if not a)
        out.cutbacks = out.failed_solves  # load_path halves once per failed solve
        if out.increments:
            out.max_force_error = max(
                abs(i.contact_force[2] + i.applied_force[2]) / abs(i.applied_force[2])
                for i in out.increments)
            out.real_area_fraction = max(i.real_area for i in out.increments) / self.contact_area
        out.dissipation = interface.dissipation()
        out.dissipation_bound = bound
        out.min_pressure, out.max_pressure, out.min_point_dissipation = min_p, max_p, min_d
        out.max_point_dissipation = max_d
        out.wall_time = time.perf_counter() - t0
        solver.destroy()
        comm.barrier()
        rows = None
        if comm.rank == 0 and os.path.exists(writer.csv_path):
            with open(writer.csv_path, newline="") as fh:
                rows = list(csv.DictReader(fh))
        out.csv_rows = comm.bcast(rows, root=0)
        return out


def table(outcomes) -> str:
    """Markdown table of the outcomes (the one in docs/extremes.md)."""
    lines = ["| case | converged | cutbacks | Newton its (max/median) | max force error | "
             "dissipation D [N mm] | D bound [N mm] | max p [MPa] | max A/A0 (patch mean) | points below validity (max) | run time [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for o in outcomes:
        mx, md = o.newton
        conv = "yes" if o.converged else f"no: stops at load factor {o.failed_factor:.4g} " \
                                         f"(last converged {o.last_converged:.4g})"
        lines.append(f"| {o.case.name} | {conv} | {o.cutbacks} | {mx} / {md:g} | "
                     f"{o.max_force_error:.1e} | {o.dissipation:.4g} | {o.dissipation_bound:.3g} | "
                     f"{o.max_pressure:.4g} | "
                     f"{o.real_area_fraction:.3g} | {o.max_below_validity} / {o.n_points} | "
                     f"{o.wall_time:.1f} |")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------- tests
@pytest.fixture(scope="module")
def scene():
    # silence the INFO lines of the JIT compiler
    logging.getLogger().addFilter(lambda r: r.levelno >= logging.WARNING)
    return Scene(MPI.COMM_WORLD)


@pytest.fixture(scope="module")
def outcomes():
    return {}


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    comm = MPI.COMM_WORLD
    path = str(tmp_path_factory.mktemp("extremes")) if comm.rank == 0 else None
    return comm.bcast(path, root=0)


def check_outcome(o: Outcome) -> None:
    """The contract of every run (see the module docstring)."""
    name = o.case.name
    n_conv = len(o.increments)
    # the CSV exists, parses and has one row per converged increment
    assert o.csv_rows is not None or n_conv == 0, f"{name}: history.csv missing"
    rows = o.csv_rows or []
    assert len(rows) == n_conv, f"{name}: {len(rows)} CSV rows for {n_conv} converged increments"
    for row, inc in zip(rows, o.increments):
        assert int(row["step"]) == inc.step
        assert float(row["load_factor"]) == pytest.approx(inc.load_factor, rel=1e-9)
        assert np.isfinite(float(row["contact_fz_N"]))
        assert float(row["force_error_rel"]) <= FORCE_TOL
    if o.converged:
        assert [i.target for i in o.increments][-1] == FACTORS[-1]
        reached = sorted({i.load_factor for i in o.increments})
        assert all(any(abs(r - f) < 1e-12 for r in reached) for f in FACTORS), name
    else:
        # a clean stop: the error names the load factor that could not be reached
        assert "load factor" in o.error and f"{o.failed_factor:.6g}" in o.error, o.error
        assert np.isfinite(o.failed_factor)
        if o.increments:
            assert o.increments[-1].load_factor == pytest.approx(o.last_converged)
        else:
            assert o.last_converged == 0.0
    if n_conv:
        assert o.max_force_error <= FORCE_TOL, f"{name}: force balance {o.max_force_error:.2e}"
        assert o.min_pressure >= 0.0, f"{name}: negative pressure {o.min_pressure}"
        assert o.max_pressure > 0.0, f"{name}: nothing in contact"
        assert np.isfinite(o.dissipation) and o.dissipation >= 0.0, o.dissipation
        assert o.dissipation <= o.dissipation_bound * (1 + 1e-9) + 1e-300, \
            f"{name}: D = {o.dissipation:.4g} above the bound mu_m F_N |ds_p| " \
            f"= {o.dissipation_bound:.4g}"
        # per point, the accumulated t_T . du_p is >= 0 up to round-off of the return map
        assert o.min_point_dissipation >= -1e-9 * o.max_point_dissipation, \
            f"{name}: point dissipation {o.min_point_dissipation:.3e} < 0 " \
            f"(max {o.max_point_dissipation:.3e})"
        for inc in o.increments:
            assert np.all(np.isfinite(inc.contact_force)) and np.isfinite(inc.real_area)
            assert inc.n_active > 0


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_extreme_case(scene, outcomes, workdir, case):
    """The punch converges with physical results or stops with a clean LoadStepError."""
    outdir = os.path.join(workdir, f"case{CASES.index(case):02d}")
    o = scene.run(case, outdir)
    outcomes[case.name] = o
    check_outcome(o)


def test_paper_case_converges_without_cutback(outcomes, scene, workdir):
    """Sanity: the reference case itself converges at once (else the extremes mean nothing)."""
    o = outcomes.get(CASES[0].name) or scene.run(CASES[0], os.path.join(workdir, "ref"))
    assert o.converged and o.cutbacks == 0


def test_forced_failure_stops_cleanly(outcomes, scene, workdir):
    """The deterministic clean stop: LoadStepError past step 2, converged steps in the CSV."""
    case = CASES[-1]
    assert case.forced_failure
    o = outcomes.get(case.name) or scene.run(case, os.path.join(workdir, "forced"))
    assert not o.converged
    assert 0.5 <= o.last_converged < o.failed_factor < 0.75
    assert "forced failure" in o.error
    assert o.cutbacks >= 1 and len(o.csv_rows) == len(o.increments) >= 2


def test_nearly_isotropic_surface_warns():
    """m04/m40 -> 1: the strongly anisotropic model is out of its range; the library must warn."""
    from rough_contact.surface import SpectralMoments

    with pytest.warns(UserWarning, match="(?i)anisotrop"):
        SpectralMoments(**ISOTROPIC_MOMENTS_UM, unit="um")


def test_summary_table(outcomes):
    """Print the table of docs/extremes.md (visible with ``pytest -s``)."""
    done = [outcomes[c.name] for c in CASES if c.name in outcomes]
    PETSc.Sys.Print("\n" + table(done))
    assert done


# ---------------------------------------------------------------------------------- runner
def main(names=None, cases=CASES) -> list:
    """Run every case (or those named) and print the Markdown table. Collective."""
    comm = MPI.COMM_WORLD
    sc = Scene(comm)
    path = tempfile.mkdtemp(prefix="rc_extremes_") if comm.rank == 0 else None
    path = comm.bcast(path, root=0)
    res = []
    for i, case in enumerate(cases):
        if names and case.name not in names:
            continue
        o = sc.run(case, os.path.join(path, f"case{i:02d}"))
        check_outcome(o)
        res.append(o)
        PETSc.Sys.Print(f"{case.name}: converged={o.converged} cutbacks={o.cutbacks} "
                        f"[{o.wall_time:.1f} s] {o.error}")
    PETSc.Sys.Print(f"\n{sc.V.dofmap.index_map.size_global * 3} DOFs, "
                    f"{comm.size} rank(s), factors {FACTORS}\n")
    PETSc.Sys.Print(table(res))
    return res


if __name__ == "__main__":
    warnings.simplefilter("default")
    logging.getLogger().addFilter(lambda r: r.levelno >= logging.WARNING)
    args = sys.argv[1:]
    if "--probes" in args:
        args.remove("--probes")
        main(args or None, cases=PROBES)
    else:
        main(args or None)
