"""rough_contact.io.plotting: what the figures hold (the data of their lines, collections, colour
scales and labels, read back from the matplotlib objects), PNGs written, loop energies against
an analytic loop."""

from __future__ import annotations

import numpy as np
import pytest

from rough_contact.io import plotting

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"

# two triangles and one quadrilateral on z = 0 (a 2 x 1 strip), and a point cloud
POINTS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]], float)
TRIS = np.array([[0, 1, 2], [0, 2, 3]])
QUADS = np.array([[1, 4, 5, 2]])


def assert_png(path):
    with open(path, "rb") as fh:
        assert fh.read(8) == PNG_MAGIC


def test_import_needs_neither_matplotlib_nor_fe_stack(imports_without):
    imports_without(["rough_contact.io.plotting"], also={"matplotlib"})


@pytest.mark.parametrize("cells", [TRIS, QUADS, None])
def test_pressure_and_status_maps(tmp_path, cells):
    n = len(POINTS) if cells is None else len(cells)
    values = np.linspace(0.0, 3.0, n)
    fig = plotting.plot_pressure_map(POINTS, cells, values, title="p", path=tmp_path / "p.png")
    assert_png(tmp_path / "p.png")
    ax, cbar_ax = fig.axes
    (drawn,) = ax.collections
    # one colour value per facet (per point without cells), in order, scaled to the data range
    np.testing.assert_array_equal(np.asarray(drawn.get_array()), values)
    if n > 1:
        assert (drawn.norm.vmin, drawn.norm.vmax) == (0.0, 3.0)
    else:                       # one value: a band around it
        assert drawn.norm.vmin < values[0] < drawn.norm.vmax
    assert cbar_ax.get_ylabel() == "contact pressure p [MPa]"
    assert ax.get_title() == "p"
    if cells is not None:       # the polygons are the facets projected on z = 0
        paths = [pth.vertices[:len(c)] for pth, c in zip(drawn.get_paths(), cells)]
        for verts, c in zip(paths, cells):
            np.testing.assert_array_equal(verts, POINTS[c][:, :2])
    status = np.arange(n) % 3
    fig = plotting.plot_status_map(POINTS, cells, status, path=tmp_path / "s.png")
    assert_png(tmp_path / "s.png")
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert [t.split()[0] for t in legend] == ["open", "stick", "slip"]


def test_status_shares_are_area_weighted(tmp_path):
    # triangles of area 0.5 each and the quadrilateral of area 1: stick 1/4, slip 1/4, open 1/2
    cells = [TRIS[0], TRIS[1]]
    fig = plotting.plot_status_map(POINTS, np.array(cells), np.array([1, 2]))
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert texts == ["open 0 %", "stick 50 %", "slip 50 %"]
    quad_fig = plotting.plot_status_map(POINTS[[1, 4, 5, 2]], np.array([[0, 1, 2, 3]]),
                                        np.array([0]))
    texts = [t.get_text() for t in quad_fig.axes[0].get_legend().get_texts()]
    assert texts[0] == "open 100 %"


def test_uniform_field_and_projection(tmp_path):
    pts = POINTS[:, [0, 2, 1]]  # the strip in the plane y = 0
    fig = plotting.plot_facet_field(pts, TRIS, np.full(2, 2.0), path=tmp_path / "u.png")
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x [mm]", "z [mm]")
    # a uniform field keeps a non-degenerate colour scale centred on its value
    norm = ax.collections[0].norm
    assert norm.vmin < 2.0 < norm.vmax and norm.vmin + norm.vmax == pytest.approx(4.0)
    assert_png(tmp_path / "u.png")


def test_slip_quiver(tmp_path):
    rng = np.random.default_rng(1)
    pts = np.column_stack([rng.random((500, 2)), np.zeros(500)])
    vec = np.column_stack([rng.normal(size=(500, 2)) * 1e-3, np.zeros(500)])
    fig = plotting.plot_slip_quiver(pts, vec, max_arrows=64, path=tmp_path / "q.png")
    assert_png(tmp_path / "q.png")
    quiver = [c for c in fig.axes[0].collections if type(c).__name__ == "Quiver"][0]
    assert 1 <= len(quiver.U) <= 64
    plotting.plot_slip_quiver(POINTS, np.ones((2, 3)), cells=TRIS, normalize=False,
                              path=tmp_path / "q2.png")
    assert_png(tmp_path / "q2.png")


def parallelogram_loop(F0, k, U, n_cycles, per_branch=7):
    """Coulomb friction with an elastic spring k: stick branches of slope k between -F0 and
    F0, slip at +-F0 out to +-U; starts at (-U, -F0)."""
    du = 2.0 * F0 / k
    corners = [(-U, -F0), (-U + du, F0), (U, F0), (U - du, -F0), (-U, -F0)]
    u, f = [corners[0][0]], [corners[0][1]]
    for _ in range(n_cycles):
        for (u0, f0), (u1, f1) in zip(corners[:-1], corners[1:]):
            s = np.linspace(0, 1, per_branch)[1:]
            u += list(u0 + s * (u1 - u0))
            f += list(f0 + s * (f1 - f0))
    return np.array(u), np.array(f)


def test_loop_energy_equals_parallelogram_area(tmp_path):
    F0, k, U = 40.0, 2.0e4, 6e-3
    u, f = parallelogram_loop(F0, k, U, n_cycles=2)
    b = plotting.split_cycles(u)
    assert len(b) == 3  # start, the turn at -U, end
    energies = plotting.loop_energies(u, f, b)
    exact = 4.0 * F0 * (U - F0 / k)  # base 2F0 times width 2(U - F0/k)
    assert np.allclose(energies, exact, rtol=1e-12)
    fig = plotting.plot_hysteresis(u, f, path=tmp_path / "h.png")
    assert_png(tmp_path / "h.png")
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert len(labels) == 2 and f"{exact:.4g}" in labels[0]
    # one line per cycle, together covering the whole path (the turning point in both)
    cycles = [ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("cycle")]
    assert len(cycles) == 2
    np.testing.assert_array_equal(np.concatenate([cycles[0].get_xdata(),
                                                  cycles[1].get_xdata()[1:]]), u)
    np.testing.assert_array_equal(cycles[1].get_ydata(), f[b[1]:])


def sliding_spring(u, F0, k):
    """Force of a spring k in series with a Coulomb slider F0 along the path u (starting
    unloaded): the elastic-perfectly-sliding joint whose steady loop is a parallelogram."""
    f = np.zeros_like(u)
    for i in range(1, len(u)):
        f[i] = np.clip(f[i - 1] + k * (u[i] - u[i - 1]), -F0, F0)
    return f


def program_path(cycles=3, steps=16, a=8e-3, F0=40.0, k=2e4):
    """A preload + ``cycles`` triangle cycles of amplitude ``a`` [mm] (16 increments per cycle:
    u moves by a / 4 per increment) through the sliding spring; F0 / k = a / 4, so the stick
    range 2 F0 / k after a reversal ends on an increment and the sampled path is the exact
    parallelogram (the trapezoidal loop area is then exact)."""
    from rough_contact.solver.program import preload_then_cyclic

    prog = preload_then_cyclic(2, cycles, steps)
    u = a * np.array([prog.channels["cyclic"](t) for t in prog.times])
    return prog, u, sliding_spring(u, F0, k)


def test_plotted_cycles_are_the_programs_cycles(tmp_path):
    """Issue 24 item 16: a 3-cycle program (0 -> +a -> -a -> 0 per cycle) plots as 3 closed
    loops when its cycle boundaries are passed; without them the path is cut at the minima into
    4 pieces, the first and last open, and those get no loop energy in the legend."""
    from rough_contact.solver.program import cycle_boundaries

    a, F0, k = 8e-3, 40.0, 2e4
    prog, u, f = program_path(a=a, F0=F0, k=k)
    b = cycle_boundaries(prog.times, prog)
    # the preload ends at increment 1 (t = 1); cycle c ends at t = 1 + c, 16 increments later
    assert b.tolist() == [1, 17, 33, 49]
    fig = plotting.plot_hysteresis(u, f, boundaries=b, path=tmp_path / "loops.png")
    assert_png(tmp_path / "loops.png")
    lines = [ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("cycle")]
    assert [ln.get_label().split(":")[0] for ln in lines] == ["cycle 1", "cycle 2", "cycle 3"]
    for c, ln in enumerate(lines, start=1):
        np.testing.assert_array_equal(ln.get_xdata(), u[b[c - 1]:b[c] + 1])
        np.testing.assert_array_equal(ln.get_ydata(), f[b[c - 1]:b[c] + 1])
        assert ln.get_xdata()[0] == ln.get_xdata()[-1] == 0.0        # closed: from 0 to 0
    exact = 4.0 * F0 * (a - F0 / k)                                  # the parallelogram
    for ln in lines[1:]:                                             # cycle 1 starts unloaded
        assert f"{exact:.4g}" in ln.get_label()
    # only the last cycle, numbered as in the program
    fig = plotting.plot_hysteresis(u, f, boundaries=b, cycles=[3])
    assert [ln.get_label().split(":")[0] for ln in fig.axes[0].get_lines()
            if ln.get_label()[:1] in "cp"] == ["cycle 3"]
    with pytest.raises(ValueError, match="cycles \\[4\\] are invalid: the path has cycles 1 .. 3"):
        plotting.plot_hysteresis(u, f, boundaries=b, cycles=[4])
    # the old call: split at the minima -> 4 pieces, 2 of them open paths without a loop energy
    fig = plotting.plot_hysteresis(u, f)
    labels = [ln.get_label() for ln in fig.axes[0].get_lines() if ln.get_label()[:1] in "cp"]
    assert len(labels) == 4
    assert ["open path" in lab for lab in labels] == [True, False, False, True]
    assert not any("oint" in lab for lab in labels if "open path" in lab)


def test_cycle_summary_energy_ratio_of_a_parallelogram_and_a_rectangle():
    """A = E_d / (4 F* delta*): 1 - delta_s / delta* = 3/4 for the sampled parallelogram of
    the sliding spring (delta_s = F0 / k = a / 4; E_d = 4 F0 (a - a / 4)), 1 for a rectangle
    (rigid-plastic sliding: E_d = 2 F0 x 2 a), 0 for an elastic line."""
    from rough_contact.cycles import energy_ratio, loop_amplitudes, loop_energies
    from rough_contact.solver.program import cycle_summary

    a, F0, k = 8e-3, 40.0, 2e4
    prog, u, f = program_path(a=a, F0=F0, k=k)
    rows = cycle_summary(prog.times, prog, u, f, np.zeros_like(u))
    assert [r["cycle"] for r in rows] == [1, 2, 3]
    for r in rows[1:]:
        assert r["loop_energy"] == pytest.approx(3.0 * F0 * a, rel=1e-12)
        assert (r["delta_amplitude"], r["force_amplitude"]) == (pytest.approx(a), F0)
        assert r["energy_ratio"] == pytest.approx(0.75, rel=1e-12)
        assert r["secant_stiffness"] == pytest.approx(F0 / a, rel=1e-12)
    # rectangle: 0 -> a at +F0, drop to -F0, -> -a, up to +F0, -> 0 (vertical edges: two
    # increments at the same u)
    u = a * np.array([0.0, 0.5, 1.0, 1.0, 0.0, -1.0, -1.0, 0.0])
    f = F0 * np.array([1.0, 1.0, 1.0, -1.0, -1.0, -1.0, 1.0, 1.0])
    b = [0, 7]
    E = loop_energies(u, f, b)
    du, df = loop_amplitudes(u, f, b)
    assert E[0] == pytest.approx(4.0 * F0 * a, rel=1e-14)
    assert energy_ratio(E, df, du)[0] == pytest.approx(1.0, rel=1e-14)
    # elastic line: no area
    u = a * np.array([0.0, 1.0, 0.0, -1.0, 0.0])
    assert energy_ratio(loop_energies(u, 1e4 * u, [0, 4]), *loop_amplitudes(u, 1e4 * u, [0, 4]))[
        0] == pytest.approx(0.0, abs=1e-15)
    with pytest.raises(ValueError, match="force_amplitude -1 N"):
        energy_ratio(1.0, -1.0, 1.0)


def test_cycle_boundaries_of_an_incomplete_run():
    """A run stopped inside cycle 3 has two complete cycles; before cycle 1 ends, none."""
    from rough_contact.solver.program import cycle_boundaries, preload_then_cyclic

    prog = preload_then_cyclic(2, 3, 8)
    assert cycle_boundaries(prog.times[:22], prog).tolist() == [1, 9, 17]
    assert cycle_boundaries(prog.times[:8], prog).size == 0
    assert cycle_boundaries(prog.times, prog).tolist() == [1, 9, 17, 25]


def test_fretting_map(tmp_path):
    fig = plotting.plot_fretting_map([0.3, 0.5, 1.0, 4.0], [0.0, 0.03, 0.3, 0.74],
                                     [0.0, 1.0, 1.0, 1.0], transition=0.5,
                                     references={"parallelogram": ([1.0, 4.0], [0.1, 0.77])},
                                     path=tmp_path / "map.png")
    assert_png(tmp_path / "map.png")
    ax0, ax1 = fig.axes
    np.testing.assert_array_equal(ax0.get_lines()[0].get_ydata(), [0.0, 0.03, 0.3, 0.74])
    np.testing.assert_array_equal(ax1.get_lines()[0].get_ydata(), [0.0, 100.0, 100.0, 100.0])
    with pytest.raises(ValueError, match="slip_fraction"):
        plotting.plot_fretting_map([1.0], [0.1], [1.5])
    with pytest.raises(ValueError, match="amplitude"):
        plotting.plot_fretting_map([0.0], [0.1], [0.5])


def test_split_cycles_with_flat_steps():
    u = np.array([0.0, 1.0, 1.0, 0.0, -1.0, -1.0, -1.0, 0.0, 1.0, 0.0])
    assert plotting.split_cycles(u).tolist() == [0, 4, 9]
    assert plotting.split_cycles(np.zeros(3)).tolist() == [0, 2]


def test_load_displacement(tmp_path):
    u = np.linspace(0, 1e-3, 5)
    fig = plotting.plot_load_displacement({"P1": (u, 1e5 * u), "P2": (u, 0.9e5 * u)},
                                          ylabel="P [N]", path=tmp_path / "ld.png")
    assert_png(tmp_path / "ld.png")
    (ax,) = fig.axes
    lines = ax.get_lines()
    assert [ln.get_label() for ln in lines] == ["P1", "P2"]       # drawn in the given order
    for ln, slope in zip(lines, (1e5, 0.9e5)):
        np.testing.assert_array_equal(ln.get_xdata(), u)
        np.testing.assert_allclose(ln.get_ydata(), slope * u, rtol=1e-15)
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("displacement [mm]", "P [N]")
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["P1", "P2"]


def test_bad_input():
    with pytest.raises(ValueError, match="values .* shape"):
        plotting.plot_pressure_map(POINTS, TRIS, np.ones(3))
    with pytest.raises(ValueError, match="cell vertex indices"):
        plotting.plot_pressure_map(POINTS, np.array([[0, 1, 9]]), np.ones(1))
    with pytest.raises(ValueError, match="status"):
        plotting.plot_status_map(POINTS, TRIS, np.array([0, 3]))
    with pytest.raises(ValueError, match="non-finite"):
        plotting.plot_pressure_map(POINTS, TRIS, np.array([1.0, np.nan]))
    with pytest.raises(ValueError, match="axes"):
        plotting.plot_pressure_map(POINTS, TRIS, np.ones(2), axes="xw")
    with pytest.raises(ValueError, match="boundaries"):
        plotting.loop_energies(np.arange(4.0), np.ones(4), [0, 5])
    with pytest.raises(ValueError, match="curves"):
        plotting.plot_load_displacement({})
