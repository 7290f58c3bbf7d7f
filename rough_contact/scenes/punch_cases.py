"""The flat punch's three friction cases of section 9.2 (Table 5, Figs 18-19): one run per case
and its post-processing — dissipation (cumulative and the paper's literal definition), plastic
slip quivers and stick/slip maps, the reversal of tangential tractions on unloading, and the
mirror x <-> y asymmetry.

Cases (n_x = n_y = 275 /mm; the surface, materials and load of :mod:`.flat_punch`):
(a) mu_m = 0.2, mu_o = 1, nu = 0.125, kT = 0.7 kN; (b) mu_m = 0.5, mu_o = 0.5, nu = 0.125,
kT = 0.7 kN; (c) as (b) with kTx = 0.7 kN, kTy = kN.

Units: mm, N, MPa; dissipation N mm. Library code (no petsc4py.init, no sys.argv).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from mpi4py import MPI

from rough_contact.io import gather_points
from rough_contact.scenes import flat_punch as demo
from rough_contact.solver.loading import load_path, load_unload_factors

__all__ = ["Snapshot", "CaseIncrement", "PunchCaseResult", "snapshot", "mirror_asymmetry",
           "run_case", "plot_case", "plot_unloading", "summary_table"]

FLIP = np.array([1.0, -1.0])  # local (x, y) -> global (x, y): y_local = n x x = -y_global


@dataclass(frozen=True)
class Snapshot:
    """All interface points (gathered on rank 0) in GLOBAL x, y axes.

    Attributes:
        x: (n, 2) point coordinates [mm].
        w: (n,) weights (nominal area) [mm^2].
        t: (n, 2) tangential traction on the punch surface (energy-conjugate,
            t = dpsi/djump; the force per area on the punch is +t) [MPa].
        sp: (n, 2) plastic slip (u_foundation - u_punch) [mm].
        s: (n, 2) total slip [mm].
        p: (n,) pressure [MPa].
        slipping: (n,) bool.
        D: (n,) cumulative dissipation per area [N/mm].
    """

    x: np.ndarray
    w: np.ndarray
    t: np.ndarray
    sp: np.ndarray
    s: np.ndarray
    p: np.ndarray
    slipping: np.ndarray
    D: np.ndarray


@dataclass(frozen=True)
class CaseIncrement:
    """One converged increment of :func:`run_case`.

    Attributes:
        load_factor: 1 = 1000 N on the whole punch.
        n_slipping: slipping interface points.
        D: cumulative dissipation of the quarter model [N mm].
        Fx, Fy: tangential interface force on the quarter punch [N].
        iterations: Newton iterations.
        reversed_fraction: on unloading, the contact area whose traction points against its
            peak-load direction / the contact area [-] (nan before the peak).
    """

    load_factor: float
    n_slipping: int
    D: float
    Fx: float
    Fy: float
    iterations: int
    reversed_fraction: float


@dataclass(frozen=True)
class PunchCaseResult:
    """Result of :func:`run_case`: identical on every rank, except ``peak`` and ``end``
    (the :class:`Snapshot` at the full load and at the end), present on rank 0 only (``None``
    elsewhere). Dissipations of the quarter model [N mm].

    Attributes:
        case: friction case "a", "b" or "c".
        num_dofs, n_points: global numbers of DOFs and interface points.
        cell_type, mesh_size, contact_size, order, steps, n_unload, normal_law: the run's
            settings (sizes in mm).
        D_peak, D_end: cumulative dissipation at the peak and at the end.
        D_literal_peak: the paper's definition, sum of t_T . u^p_T w at the peak.
        max_plastic_slip_peak, mean_plastic_slip_peak: largest / area-weighted mean |u^p_T|
            at the peak [mm].
        slip_area_fraction_peak: slipping area / patch area at the peak [-].
        first_reversal_load_factor: the largest load factor on unloading at which some contact
            area has its traction reversed (nan if none).
        reversed_fraction_end: reversed-traction area fraction at the end [-].
        slip_sign_kept_fraction: of the area whose traction reversed, the part whose total slip
            kept its peak sign [-] (nan if none reversed).
        mirror_peak, mirror_end: x <-> y mirror defects (:func:`mirror_asymmetry`).
        history: the increments (:class:`CaseIncrement`).
        wall_time: [s].
    """

    case: str
    num_dofs: int
    n_points: int
    cell_type: str
    mesh_size: float
    contact_size: float
    order: int
    steps: int
    n_unload: int
    normal_law: str
    D_peak: float
    D_end: float
    D_literal_peak: float
    max_plastic_slip_peak: float
    mean_plastic_slip_peak: float
    slip_area_fraction_peak: float
    first_reversal_load_factor: float
    reversed_fraction_end: float
    slip_sign_kept_fraction: float
    mirror_peak: tuple
    mirror_end: tuple
    history: list
    wall_time: float
    peak: Optional[Snapshot] = None
    end: Optional[Snapshot] = None


def snapshot(comm, interface) -> Optional[Snapshot]:
    """All interface points gathered on rank 0 (:class:`Snapshot`); None on other ranks.
    Collective."""
    pf = interface.point_fields()
    pts, f = gather_points(comm, interface.point_coordinates(), {
        "w": pf.weight, "t": pf.shear * FLIP, "sp": pf.plastic_slip * FLIP,
        "s": pf.slip * FLIP, "p": pf.pressure, "slipping": pf.slipping.astype(float),
        "D": pf.dissipation})
    if comm.rank != 0:
        return None
    f["slipping"] = f["slipping"] > 0.5
    return Snapshot(x=pts[:, :2], **f)


def mirror_asymmetry(snap, tol=1e-7):
    """Relative x <-> y mirror defect of the plastic slip and the traction (rank 0).

    Each point (x, y) is paired with the point nearest to (y, x); a vector field v is
    symmetric when v(y, x) = (v_y, v_x)(x, y). Returns (max pairing distance [mm],
    defect of sp, defect of t), defects as max |difference| / max |field|.
    """
    from scipy.spatial import cKDTree

    x = snap.x
    dist, j = cKDTree(x).query(x[:, ::-1])
    out = [float(dist.max())]
    for v in (snap.sp, snap.t):
        scale = np.abs(v).max()
        out.append(float(np.abs(v[j] - v[:, ::-1]).max() / scale) if scale > 0 else 0.0)
    return tuple(out)


def run_case(case, comm=MPI.COMM_WORLD, mesh_size=10.0, contact_size=1.0, order=1,
             cell_type="hexahedron", load_half_width=2.5, steps=16, n_unload=None,
             final_factor=None, normal_law="elasto-plastic", prefix="punch_case_", verbose=False):
    """One friction case through loading and unloading. Collective.

    Loading in ``steps`` increments to 1000 N, then ``n_unload`` (default steps - 1) increments
    down to the load factor ``final_factor`` (default 1/steps).

    Returns:
        :class:`PunchCaseResult` (snapshots on rank 0 only).
    """
    t0 = MPI.Wtime()
    n_unload = steps - 1 if n_unload is None else n_unload
    m = demo.build(comm=comm, mesh_size=mesh_size, contact_size=contact_size, order=order,
                   load_half_width=load_half_width, law="rough", case=case,
                   normal_law=normal_law, steps=steps, prefix=prefix, cell_type=cell_type)
    interface, problem, solver = m.interface, m.problem, m.solver
    factors = load_unload_factors(steps, n_unload, final_factor)
    history, peak, snap = [], None, None
    for inc in load_path(problem, solver, factors, verbose=verbose):
        if not np.isclose(inc.contact_force[2], -inc.applied_force[2], rtol=1e-6):
            raise RuntimeError(f"force balance violated at load factor {inc.load_factor}")
        snap = snapshot(comm, interface)
        reversed_fraction = float("nan")
        if inc.load_factor == 1.0 and inc.target == 1.0:
            peak = snap
        elif peak is not None and comm.rank == 0:
            # contact area whose traction points against its peak-load direction
            rev = np.einsum("ij,ij->i", snap.t, peak.t) < 0.0
            reversed_fraction = float(snap.w[rev].sum() / snap.w.sum())
        history.append(CaseIncrement(
            load_factor=inc.load_factor, n_slipping=inc.n_slipping, D=inc.dissipation,
            Fx=float(inc.contact_force[0]), Fy=float(inc.contact_force[1]),
            iterations=inc.iterations, reversed_fraction=reversed_fraction))
    D_end = interface.dissipation()
    D_peak = next(r.D for r in history if r.load_factor == 1.0)
    figures = None
    if comm.rank == 0:   # the figures of the gathered points, then copied to every rank
        figures = dict(history=history, **_peak_figures(history, peak, snap))
    figures = comm.bcast(figures, root=0)
    solver.destroy()
    return PunchCaseResult(
        case=case, num_dofs=problem.num_dofs, n_points=interface.n_points_global,
        cell_type=cell_type, mesh_size=mesh_size, contact_size=contact_size, order=order,
        steps=steps, n_unload=n_unload, normal_law=normal_law, D_peak=D_peak, D_end=D_end,
        wall_time=MPI.Wtime() - t0, peak=peak, end=snap, **figures)


def _peak_figures(history, peak: Snapshot, snap: Snapshot) -> dict:
    """The figures of :class:`PunchCaseResult` computed from the snapshots (rank 0)."""
    area = peak.w.sum()
    rev = [r.load_factor for r in history
           if np.isfinite(r.reversed_fraction) and r.reversed_fraction > 0]
    # of the area whose traction reversed, the part whose total slip kept its peak sign
    rev_end = np.einsum("ij,ij->i", snap.t, peak.t) < 0.0
    kept = rev_end & (np.einsum("ij,ij->i", snap.s, peak.s) > 0.0)
    return dict(
        D_literal_peak=float(np.sum(np.einsum("ij,ij->i", peak.t, peak.sp) * peak.w)),
        max_plastic_slip_peak=float(np.linalg.norm(peak.sp, axis=1).max()),
        mean_plastic_slip_peak=float(np.sum(np.linalg.norm(peak.sp, axis=1) * peak.w) / area),
        slip_area_fraction_peak=float(peak.w[peak.slipping].sum() / area),
        first_reversal_load_factor=max(rev) if rev else float("nan"),
        reversed_fraction_end=history[-1].reversed_fraction,
        slip_sign_kept_fraction=(float(snap.w[kept].sum() / snap.w[rev_end].sum())
                                 if rev_end.any() else float("nan")),
        mirror_peak=mirror_asymmetry(peak), mirror_end=mirror_asymmetry(snap))


# ## Figures (rank 0), drawn with rough_contact.io.plotting
def plot_case(res, path):
    """Three panels: plastic slip directions at peak, after unloading; stick/slip at peak."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from rough_contact.io import plotting

    fig = Figure(figsize=(15, 4.8))
    FigureCanvasAgg(fig)
    axs = fig.subplots(1, 3)
    for ax, snap, when in ((axs[0], res.peak, "at 1000 N"), (axs[1], res.end, "after unloading")):
        plotting.plot_slip_quiver(snap.x, snap.sp, max_arrows=100, scale=1e6,
                                  label="|plastic slip| [nm]", ax=ax,
                                  title=f"case ({res.case}): plastic slip directions {when}")
    pk = res.peak
    status = np.where(pk.p > 0, 1 + pk.slipping.astype(int), 0)
    plotting.plot_status_map(pk.x, None, status, weights=pk.w, ax=axs[2], point_size=40,
                             title=f"case ({res.case}): stick/slip at 1000 N")
    fig.suptitle("Quarter punch, patch [0,10]^2 mm (centre at the origin); arrows: direction of "
                 "u^p_T (foundation - punch), colour: magnitude", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def plot_unloading(results, path):
    """Reversed-traction area fraction and tangential resultant Fx vs load factor."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    for res in results:
        h = res.history
        lam = np.array([r.load_factor for r in h])
        n_load = res.steps
        un = np.arange(len(h)) >= n_load - 1  # peak and the unloading steps
        rf = np.array([0.0 if not np.isfinite(r.reversed_fraction) else r.reversed_fraction
                       for r in h])
        axs[0].plot(lam[un], 100 * rf[un], "o-", ms=3, label=f"case ({res.case})")
        fx = np.array([r.Fx for r in h])
        fy = np.array([r.Fy for r in h])
        axs[1].plot(lam, fx, "-", label=f"case ({res.case}) Fx")
        axs[1].plot(lam, fy, "--", label=f"case ({res.case}) Fy")
    axs[0].set_xlabel("load factor on unloading (1 = 1000 N)")
    axs[0].set_ylabel("contact area with reversed t_T [%]")
    axs[0].invert_xaxis()
    axs[0].legend(fontsize=8)
    axs[0].set_title("tangential traction opposite to its peak-load direction", fontsize=9)
    axs[1].set_xlabel("load factor")
    axs[1].set_ylabel("tangential resultant on the quarter punch [N]")
    axs[1].legend(fontsize=7)
    axs[1].set_title("tangential interface force (loading and unloading)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def summary_table(results):
    """Markdown table of the measured figures beside Table 5 (rank 0)."""
    lines = ["| case | D_cum peak (quarter) | D_cum end (quarter) | D_lit peak (quarter) | "
             "x4 (whole punch, D_cum end) | Table 5 21-node | Table 5 28-node | "
             "max u^p peak [um] | slip area peak | reversed t_T area end | mirror defect sp peak "
             "| slip sign kept (reversed area) | DOFs / points | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        c = r.case
        lines.append(
            f"| ({c}) | {r.D_peak:.3e} | {r.D_end:.3e} | {r.D_literal_peak:.3e} | "
            f"{4 * r.D_end:.3e} | {demo.TABLE5['21-node'][c]} | {demo.TABLE5['28-node'][c]} | "
            f"{r.max_plastic_slip_peak * 1e3:.4f} | {100 * r.slip_area_fraction_peak:.1f} % "
            f"| {100 * r.reversed_fraction_end:.1f} % | {r.mirror_peak[1]:.2e} | "
            f"{100 * r.slip_sign_kept_fraction:.1f} % | {r.num_dofs} / {r.n_points} | "
            f"{r.wall_time:.1f} |")
    return "\n".join(lines)


