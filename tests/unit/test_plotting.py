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
