"""The law advisor on the punch and beam scenes: full model vs advised law, five surfaces.

For each surface (the paper's Table 1 and Table 2 surfaces, a nearly isotropic one, a high
plasticity index one, a heavily loaded one beyond 10 % real area) and each scene (the quarter
flat punch of section 9.2, the half beam of section 9.1; coarse P1 meshes), the advisor
(rough_contact.advisor.advise, tolerance 5 %) picks a normal law over the scene's pressure range;
the scene then runs with the full model (the fullest statistical law that applies to the surface,
``Advice.full_normal``) and with the advised law, and the table compares their FE results:

* force distribution: max over the interface points of |p_adv - p_full| / max p_full at the peak
  load (same mesh, same points);
* real contact area: sum of w A/A0 over the points at the peak;
* dissipation: total frictional dissipation at the end of the path (punch: load and unload);
* approach: area-weighted mean change of the interface gap from the first increment to the peak.

The next cheaper law, which the advisor refused, is run as well; its largest FE difference from
the full model (last column) shows whether the refusal was needed.

Wall times: the law's table build and the FE solve of each run, and the advisor's own time with
its ratio to the cheapest table build of the same surface (the elastic anisotropic table, the
cheapest one that needs the population integral; McCool's GW table is a closed form).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_advisor.py [--tolerance 0.05]
        [--surfaces ...] [--scenes punch beam] [--csv FILE] [--results ...] [--cost-only]
        [--cold N] [--bem-check]

``--cost-only`` skips the FE runs and prints only the advisor's own cost against the elastic
table's build of the same surface and modulus (each the fastest of ``--repeat`` interleaved
runs, so that a busy machine slows both alike; wall and CPU time of the process, the CPU
time being the less disturbed by other jobs on a shared machine). These are warm calls: the
process has already run the advisor once.

``--cold N`` measures what a run meets instead (the demos call the advisor once per process):
per surface and scene, N pairs of fresh processes, interleaved: one calls the advisor (the
first population sum of the process, then the same call again, warm) and builds the elastic
table; the other builds the table alone. The first population sum of a process pays one-time
costs (importing scipy.interpolate, the cached spline of the asperity shape factors, quadrature
nodes) which the table build pays when it comes first; the run's extra time for the advisor is
the first process's advisor + build minus the second's build. CPU time of each process (a
shared machine inflates wall times unevenly), medians of N.

Units: mm, N, MPa.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
import warnings

import petsc4py
from _common import write_csv

petsc4py.init(sys.argv)

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from rough_contact.advisor import RESULTS_ALL, advise, scene_pressure_range  # noqa: E402
from rough_contact.interface.normal import NormalLaw  # noqa: E402
from rough_contact.micro.asperity import AsperityMaterial  # noqa: E402
from rough_contact.scenes import beam, flat_punch  # noqa: E402
from rough_contact.solver.loading import load_path, load_unload_factors  # noqa: E402
from rough_contact.surface import SpectralMoments, example_surfaces  # noqa: E402

TABLE1 = dict(m00=0.625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)
TABLE2 = dict(m00=3.0, m20=1.0, m02=81.0, m40=1.0, m04=6561.0)
CAPTION = dict(Y=2070.0, K_Y=1.62, psi=0.35, ch=0.967, omega_p_ratio=45.0)   # Figs 18-19


def _scaled(m: SpectralMoments, c: float) -> SpectralMoments:
    """Heights times c: every moment times c^2 (bandwidths unchanged)."""
    return SpectralMoments(m.m00 * c * c, m.m20 * c * c, m.m02 * c * c, m.m40 * c * c,
                           m.m04 * c * c, unit="mm")


def surfaces():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        aniso = example_surfaces()["anisotropic"][0]
        return {
            "Table 1 (paper, caption data)": (SpectralMoments(**TABLE1, unit="um"), CAPTION),
            "Table 2 (paper), psi 0.35": (SpectralMoments(**TABLE2, unit="um"), dict(psi=0.35)),
            "nearly isotropic, psi 0.35": (SpectralMoments(m00=0.625, m20=8e-4, m02=8.4e-4,
                                                           m40=1.04e-4, m04=1.092e-4),
                                           dict(psi=0.35)),
            "Table 1, psi 5": (SpectralMoments(**TABLE1, unit="um"), dict(psi=5.0)),
            "heavily loaded (narrow band, heights x 0.009)": (_scaled(aniso, 0.009),
                                                             dict(psi=0.35)),
            # the project's reading K_Y Y = (2/pi) H: no asperity yields at these loads
            "Table 1 (paper), psi 0.35, (2/pi) H": (SpectralMoments(**TABLE1, unit="um"),
                                                   dict(psi=0.35)),
        }


def build_normal(advice, law):
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        kw = dict(n_realisations=2) if law == "bem" else {}
        normal = advice.normal_law(law, **kw)
    return normal, time.perf_counter() - t


# ## scenes: one run with a given normal law -> FE results
def run_punch(normal, comm, steps=4):
    m = flat_punch.build(comm, mesh_size=20.0, contact_size=2.5, order=1, normal=normal,
                         normal_law="elastic", steps=steps, prefix="adv_punch_")
    return _run(m.problem, m.solver, m.interface, load_unload_factors(steps, steps // 2), comm)


def run_beam(normal, comm, setup, steps=4):
    c = beam.build_case(setup, normal, 0.625, steps=steps, prefix="adv_beam_")
    return _run(c.problem, c.solver, c.interface, c.factors, comm)


def _run(problem, solver, interface, factors, comm):
    t = time.perf_counter()
    first = peak = None
    for inc in load_path(problem, solver, factors, verbose=False, validity="ignore"):
        pf = interface.point_fields()
        if first is None:
            first = pf.gap.copy()
        if inc.load_factor == max(factors) and peak is None:
            w = interface.point_weights()
            peak = dict(p=pf.pressure.copy(),
                        area=comm.allreduce(float(np.dot(w, pf.area_fraction)), op=MPI.SUM),
                        approach=comm.allreduce(float(np.dot(w, first - pf.gap)), op=MPI.SUM)
                        / interface.nominal_area())
    out = dict(peak, dissipation=interface.dissipation(), seconds=time.perf_counter() - t)
    solver.destroy()
    return out


def compare(full, adv):
    pmax = max(float(np.max(full["p"])), 1e-300)
    rel = (lambda a, b: abs(a / b - 1.0) if b != 0 else (0.0 if a == 0 else math.inf))
    return dict(force=float(np.max(np.abs(adv["p"] - full["p"]))) / pmax,
                area=rel(adv["area"], full["area"]),
                dissipation=rel(adv["dissipation"], full["dissipation"]),
                approach=rel(adv["approach"], full["approach"]))


def cost_only(cases, scenes, tolerance, results, repeat):
    """Advisor wall time / elastic table build, per surface and scene (no FE run)."""
    rows = []
    for name, (surface, mdata) in cases:
        for scene, (E, nu, p_range) in scenes.items():
            material = AsperityMaterial(E_star=E, nu=nu, **mdata)
            t_adv, t_el, c_adv, c_el = [], [], [], []

            def timed(f, wall, cpu):
                w, c = time.perf_counter(), time.process_time()
                out = f()
                wall.append(time.perf_counter() - w)
                cpu.append(time.process_time() - c)
                return out

            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)
                advise(surface, material, p_range, tolerance, results=results)   # warm-up
                for _ in range(repeat):
                    advice = timed(lambda: advise(surface, material, p_range, tolerance,
                                                  results=results), t_adv, c_adv)
                    timed(lambda: NormalLaw.elastic(surface, E), t_el, c_el)
            rows.append(dict(surface=name, scene=scene, advised=advice.normal,
                             advisor=min(t_adv), elastic_build=min(t_el),
                             advisor_ratio=min(t_adv) / min(t_el),
                             advisor_cpu=min(c_adv), elastic_build_cpu=min(c_el),
                             advisor_ratio_cpu=min(c_adv) / min(c_el)))
            print(f"-> {rows[-1]}", flush=True)
    print("\n| surface | scene | advised | advisor [ms] | elastic table build [s] "
          "| advisor / build | advisor CPU [ms] | build CPU [s] | advisor / build, CPU |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['surface']} | {r['scene']} | {r['advised']} | {r['advisor'] * 1e3:.0f} "
              f"| {r['elastic_build']:.2f} | {r['advisor_ratio']:.1%} "
              f"| {r['advisor_cpu'] * 1e3:.0f} | {r['elastic_build_cpu']:.2f} "
              f"| {r['advisor_ratio_cpu']:.1%} |")
    return rows


_COLD_CHILD = r"""
import json, sys, time, warnings
from rough_contact.advisor import advise
from rough_contact.interface.normal import NormalLaw
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.surface import SpectralMoments
spec = json.loads(sys.argv[1])
surface = SpectralMoments(**spec["surface"], unit="mm")
material = AsperityMaterial(**spec["material"])
out = {}


def timed(name, f):
    w, c = time.perf_counter(), time.process_time()
    f()
    out[name] = (time.perf_counter() - w, time.process_time() - c)


with warnings.catch_warnings():
    warnings.simplefilter("ignore", UserWarning)
    call = lambda: advise(surface, material, spec["p_range"], spec["tolerance"],  # noqa: E731
                          results=spec["results"])
    if spec["advise"]:
        timed("advisor", call)            # the first population sum of the process
        timed("advisor_again", call)      # warm
    timed("build", lambda: NormalLaw.elastic(surface, material.E_star))
print(json.dumps(out))
"""


def cold(cases, scenes, tolerance, results, n):
    """The advisor as a run meets it: fresh processes (see the module docstring)."""
    import json
    import os
    import subprocess

    def child(spec):
        out = subprocess.run([sys.executable, "-c", _COLD_CHILD, json.dumps(spec)],
                             capture_output=True, text=True, check=True,
                             env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
        return json.loads(out.stdout.splitlines()[-1])

    rows = []
    for name, (surface, mdata) in cases:
        for scene, (E, nu, p_range) in scenes.items():
            spec = dict(surface=dict(m00=surface.m00, m20=surface.m20, m02=surface.m02,
                                     m40=surface.m40, m04=surface.m04),
                        material=dict(E_star=E, nu=nu, **mdata), p_range=list(p_range),
                        tolerance=tolerance, results=list(results))
            a, b = [], []
            for _ in range(n):      # interleaved: a busy machine slows both alike
                a.append(child(dict(spec, advise=True)))
                b.append(child(dict(spec, advise=False)))
            row = dict(surface=name, scene=scene)
            for k, i in (("wall", 0), ("cpu", 1)):
                med = lambda key, runs: float(np.median([r[key][i] for r in runs]))  # noqa
                first, again = med("advisor", a), med("advisor_again", a)
                alone = med("build", b)
                # the run's extra time: advisor then build, against the build alone
                marginal = float(np.median([r["advisor"][i] + r["build"][i] for r in a])) - alone
                row.update({f"first_{k}": first, f"again_{k}": again, f"build_{k}": alone,
                            f"marginal_{k}": marginal})
            rows.append(row)
            print(f"-> {row}", flush=True)
    print("\n| surface | scene | advisor, first call of the process [ms] | the same call again "
          "[ms] | elastic table build, first in its process [s] | first call / build | run's "
          "extra time: advisor + build minus build alone [ms] | / build |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['surface']} | {r['scene']} | {r['first_cpu'] * 1e3:.0f} "
              f"| {r['again_cpu'] * 1e3:.0f} | {r['build_cpu']:.2f} "
              f"| {r['first_cpu'] / r['build_cpu']:.1%} | {r['marginal_cpu'] * 1e3:.0f} "
              f"| {r['marginal_cpu'] / r['build_cpu']:.1%} |")
    print("(CPU time of each process, medians of the runs; wall times in the CSV)")
    return rows


# (example surface, p_min, p_max [MPa], pixels per shortest wavelength) of --bem-check
BEM_CHECK_CASES = [("anisotropic", 8.0, 40.0, 4.0), ("anisotropic", 120.0, 350.0, 4.0),
                   ("self-affine", 5.0, 30.0, 2.0), ("paper", 5.0, 50.0, 2.0)]


def bem_check_table(tolerance, results):
    """advise(..., bem_check=...) on the example surfaces of docs/bem.md (E* = 1.067e5 MPa,
    psi = 0.35): the check's figures, verdict and cost beside the measured-figures verdict."""
    from rough_contact.advisor import BEMCheck

    rows = []
    for name, p0, p1, ppw in BEM_CHECK_CASES:
        s = example_surfaces()[name][0]
        mat = AsperityMaterial(E_star=1.067e5, nu=0.3, psi=0.35)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            plain = advise(s, mat, (p0, p1), tolerance, results=results)
            adv = advise(s, mat, (p0, p1), tolerance, results=results,
                         bem_check=BEMCheck(pixels_per_wavelength=ppw, cache=False))
        c = adv.bem_check
        app = c.approach_ratio[1:]
        rows.append(dict(surface=name, p_range=f"{p0:g}-{p1:g}", grid=f"{c.grid[0]}x{c.grid[1]}",
                         k_ratio=f"{c.stiffness_ratio.min():.3g}-{c.stiffness_ratio.max():.3g}",
                         k_se=f"{c.stiffness_se.min():.1%}-{c.stiffness_se.max():.1%}",
                         approach=f"{app.min():.3g}-{app.max():.3g}",
                         p_at_h=f"{c.pressure_ratio.min():.3g}-{c.pressure_ratio.max():.3g}",
                         verdict=c.verdict, measured=plain.normal, advised=adv.normal,
                         seconds=c.seconds))
        print(f"-> {rows[-1]}", flush=True)
    print("\n| surface | p range [MPa] | grid (8 realisations) | k stat/BEM at equal load "
          "| s.e. | approach | p(h) (information) | check | advised without / with the check "
          "| check [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['surface']} | {r['p_range']} | {r['grid']} | {r['k_ratio']} | {r['k_se']} "
              f"| {r['approach']} | {r['p_at_h']} | {r['verdict']} | {r['measured']} / "
              f"{r['advised']} | {r['seconds']:.1f} |")
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--tolerance", type=float, default=0.05)
    ap.add_argument("--surfaces", type=int, nargs="+", default=None,
                    help="indices (0-5) of the surfaces to run (default all)")
    ap.add_argument("--scenes", nargs="+", default=["punch", "beam"], choices=["punch", "beam"])
    ap.add_argument("--csv", default=None)
    ap.add_argument("--results", nargs="+", default=list(RESULTS_ALL),
                    choices=list(RESULTS_ALL),
                    help="the FE results the advice must keep within the tolerance (default "
                         "all, as the demos' --law auto: the table reports each)")
    ap.add_argument("--cost-only", action="store_true",
                    help="only the advisor's cost against the elastic table build (no FE)")
    ap.add_argument("--repeat", type=int, default=3, help="--cost-only: runs of each timing")
    ap.add_argument("--bem-check", action="store_true",
                    help="only the small BEM check (bem_check=True) on docs/bem.md's example "
                         "surfaces (needs Tamaas), no FE")
    ap.add_argument("--cold", type=int, default=None, metavar="N",
                    help="only the advisor's cost as a run meets it: N pairs of fresh "
                         "processes (module docstring), no FE")
    args, _ = ap.parse_known_args(argv)
    comm = MPI.COMM_WORLD
    cases = list(surfaces().items())
    if args.surfaces is not None:
        cases = [cases[i] for i in args.surfaces]
    E_punch = flat_punch.effective_modulus(flat_punch.E, flat_punch.NU, flat_punch.E,
                                           flat_punch.NU)
    scenes = {"punch": (E_punch, flat_punch.NU,
                        scene_pressure_range(250.0, 100.0, 250.0 / 16 / 100.0, 2.0)),
              "beam": (beam.E_STAR, beam.NU1,
                       scene_pressure_range(beam.TOTAL_FORCE / 2, 2500.0,
                                            beam.INITIAL_FORCE / 2 / 2500.0,
                                            beam.PRESSURE_CONCENTRATION))}
    scenes = {k: v for k, v in scenes.items() if k in args.scenes}
    results = tuple(args.results)
    if args.bem_check:
        rows = bem_check_table(args.tolerance, results)
        if args.csv:
            write_csv(args.csv, rows)
        return
    if args.cold is not None:
        rows = cold(cases, scenes, args.tolerance, results, args.cold)
        if args.csv:
            write_csv(args.csv, rows)
        return
    if args.cost_only:
        rows = cost_only(cases, scenes, args.tolerance, results, args.repeat)
        if args.csv:
            write_csv(args.csv, rows)
        return
    setup = beam.build_scene(comm, mesh_size=80.0, contact_size=20.0, order=1) \
        if "beam" in args.scenes else None
    rows = []
    for name, (surface, mdata) in cases:
        for scene in args.scenes:
            E, nu, p_range = scenes[scene]
            material = AsperityMaterial(E_star=E, nu=nu, **mdata)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)
                advice = advise(surface, material, p_range, args.tolerance, results=results)
                t = time.perf_counter()
                NormalLaw.elastic(surface, E)
                t_el = time.perf_counter() - t
            print(f"\n## {name}, {scene}\n{advice.report()}", flush=True)
            full_law, adv_law = advice.full_normal, advice.normal
            n_full, tb_full = build_normal(advice, full_law)
            res_full = (run_punch(n_full, comm) if scene == "punch"
                        else run_beam(n_full, comm, setup))
            if adv_law == full_law:
                n_adv, tb_adv, res_adv = n_full, tb_full, res_full
            else:
                n_adv, tb_adv = build_normal(advice, adv_law)
                res_adv = (run_punch(n_adv, comm) if scene == "punch"
                           else run_beam(n_adv, comm, setup))
            d = compare(res_full, res_adv)
            # the next cheaper law the advisor refused, run too: its FE difference from the full
            # model shows whether the refusal was needed
            cheaper = {"elasto-plastic": "elastic", "bem": "elastic",
                       "elastic": "greenwood_williamson"}.get(adv_law)
            refused = None
            if cheaper is not None and cheaper != full_law:
                n_ch, _ = build_normal(advice, cheaper)
                res_ch = (run_punch(n_ch, comm) if scene == "punch"
                          else run_beam(n_ch, comm, setup))
                refused = (cheaper, max(compare(res_full, res_ch).values()))
            est = {c.law: c.build_seconds for c in advice.costs}
            row = dict(surface=name, scene=scene, p_range=f"{p_range[0]:.3g}-{p_range[1]:.3g}",
                       full=full_law, advised=adv_law, A_max=advice.max_area_fraction,
                       force=d["force"], area=d["area"], dissipation=d["dissipation"],
                       approach=d["approach"], build_full=tb_full, build_adv=tb_adv,
                       est_full=est.get(full_law), est_adv=est.get(adv_law),
                       fe_full=res_full["seconds"], fe_adv=res_adv["seconds"],
                       saved=(tb_full + res_full["seconds"]) - (tb_adv + res_adv["seconds"]),
                       advisor=advice.advisor_seconds, elastic_build=t_el,
                       advisor_ratio=advice.advisor_seconds / t_el,
                       refused=refused[0] if refused else "-",
                       refused_difference=refused[1] if refused else float("nan"))
            rows.append(row)
            print(f"-> {row}", flush=True)
    print("\n| surface | scene | p range [MPa] | full | advised | max A/A0 | force distr. "
          "| real area | dissipation | approach | build full / advised [s] | FE full / advised "
          "[s] | saved [s] | advisor [ms] (/ elastic build) | cheaper law refused: its largest FE "
          "difference |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['surface']} | {r['scene']} | {r['p_range']} | {r['full']} | {r['advised']} "
              f"| {r['A_max']:.2%} | {r['force']:.2%} | {r['area']:.2%} "
              f"| {r['dissipation']:.2%} | {r['approach']:.2%} "
              f"| {r['build_full']:.2f} / {r['build_adv']:.2f} | {r['fe_full']:.1f} / "
              f"{r['fe_adv']:.1f} | {r['saved']:.1f} | {r['advisor'] * 1e3:.0f} "
              f"({r['advisor_ratio']:.0%}) | {r['refused']}: {r['refused_difference']:.1%} |")
    if args.csv:
        write_csv(args.csv, rows)


if __name__ == "__main__":
    main()
