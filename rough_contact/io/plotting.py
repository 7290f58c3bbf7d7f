"""Plots of interface results and load paths, from plain arrays (matplotlib, Agg backend).

Units are the caller's; the default labels assume the project's mm, N, MPa (slips are shown
in um). Every function builds a ``matplotlib.figure.Figure`` on the Agg canvas (no pyplot, no
window, no global state), draws into ``ax`` if one is given, saves a PNG when ``path`` is
given, and returns the figure. matplotlib is imported only when a plot is made, so importing
this module needs numpy alone.

Interface plots take either facets (``points`` (n_v, 3) and ``cells`` (n_c, 3|4) vertex
indices, values per cell: the surface of ``interface.xdmf``) or points (``cells=None``, values
per point: the quadrature-point cloud). 3D coordinates are projected on a coordinate plane:
``axes="xy"``, ``"xz"``, ``"yz"``, or ``"auto"`` (the plane across the smallest extent, i.e.
the plane of a flat interface).

* :func:`plot_facet_field` / :func:`plot_pressure_map`: flat-shaded facets with a colour bar
  and the mesh edges (what ParaView shows with "Surface With Edges").
* :func:`plot_status_map`: open / stick / slip with their share of the area.
* :func:`plot_slip_quiver`: arrows of a tangential vector field (slip, plastic slip, shear).
* :func:`plot_load_displacement`: one or more load-displacement curves.
* :func:`plot_hysteresis`: force-displacement loops with the energy of every cycle,
  :func:`loop_energies` (the closed-path integral of F du), cycles split by
  :func:`split_cycles` or given by the load program.
* :func:`plot_fretting_map`: energy ratio and slipping area share against the amplitude.
"""

from __future__ import annotations

from typing import Any, Mapping, Optional, Sequence

import numpy as np

from rough_contact.cycles import loop_energies

__all__ = ["STATUS_COLORS", "plot_facet_field", "plot_pressure_map", "plot_status_map",
           "plot_slip_quiver", "plot_load_displacement", "plot_hysteresis", "plot_fretting_map",
           "loop_energies", "split_cycles"]

STATUS_LABELS = ("open", "stick", "slip")
STATUS_COLORS = ("#d9d9d9", "#3b6fb6", "#d6452b")  # grey, blue, red
_AXES = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------
def _new_figure(ax, figsize):
    if ax is not None:
        return ax.figure, ax
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def _finish(fig, path: Optional[str], dpi: int):
    if path is not None:
        fig.tight_layout()
        fig.savefig(path, dpi=dpi)
    return fig


def _points(points) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] not in (2, 3) or not np.all(np.isfinite(p)):
        raise ValueError(f"points of shape {p.shape} must be finite (n, 2) or (n, 3) [mm]")
    return p


def _plane(points: np.ndarray, axes: str) -> tuple[np.ndarray, tuple[str, str]]:
    """2D coordinates of the points on the chosen coordinate plane and the axis names."""
    if points.shape[1] == 2:
        return points, ("x", "y")
    if axes == "auto":
        drop = int(np.argmin(np.ptp(points, axis=0))) if len(points) else 2
        pair = tuple(i for i in range(3) if i != drop)
    elif axes in _AXES:
        pair = _AXES[axes]
    else:
        raise ValueError(f"axes = {axes!r} is invalid; valid: 'auto', 'xy', 'xz', 'yz'")
    return points[:, pair], tuple("xyz"[i] for i in pair)


def _cells(cells, n_points: int) -> np.ndarray:
    c = np.asarray(cells)
    if c.ndim != 2 or c.shape[1] not in (3, 4) or not np.issubdtype(c.dtype, np.integer):
        raise ValueError(f"cells of shape {c.shape} ({c.dtype}) must be integer (n, 3) or (n, 4)")
    if c.size and (c.min() < 0 or c.max() >= n_points):
        raise ValueError(f"cell vertex indices span [{c.min()}, {c.max()}], valid [0, "
                         f"{n_points - 1}]")
    return c


def _values(values, n: int, what: str, ncomp: Optional[int] = None) -> np.ndarray:
    """Finite float array of n rows: (n,) scalars, (n, ncomp), or (n, 2|3) with ncomp=-1."""
    v = np.asarray(values, dtype=float)
    if ncomp == -1:
        ok, expected = v.ndim == 2 and v.shape[0] == n and v.shape[1] in (2, 3), f"({n}, 2|3)"
    else:
        expected = (n,) if ncomp is None else (n, ncomp)
        ok = v.shape == expected
    if not ok:
        raise ValueError(f"{what} of shape {v.shape} must be of shape {expected}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{what} holds {int(np.sum(~np.isfinite(v)))} non-finite values")
    return v


def _draw_map(ax, p2, cells, values, *, cmap, norm, edges, point_size):
    """Flat-shaded facets (or points) coloured by values; returns the mappable."""
    if cells is None:
        return ax.scatter(p2[:, 0], p2[:, 1], c=values, cmap=cmap, norm=norm, s=point_size,
                          edgecolors="none")
    from matplotlib.collections import PolyCollection

    coll = PolyCollection(p2[cells], array=values, cmap=cmap, norm=norm,
                          edgecolors="#202020" if edges else "face",
                          linewidths=0.4 if edges else 0.0)
    ax.add_collection(coll)
    ax.autoscale_view()
    return coll


def _frame(ax, names, title, unit="mm"):
    ax.set_aspect("equal")
    ax.set_xlabel(f"{names[0]} [{unit}]")
    ax.set_ylabel(f"{names[1]} [{unit}]")
    if title:
        ax.set_title(title, fontsize=10)


# --------------------------------------------------------------------------------------------
# interface maps
# --------------------------------------------------------------------------------------------
def plot_facet_field(points, cells, values, *, label: str = "", title: str = "",
                     cmap: str = "coolwarm", clim: Optional[tuple] = None, edges: bool = True,
                     axes: str = "auto", point_size: float = 12.0, ax: Any = None,
                     path: Optional[str] = None, figsize=(6.0, 5.0), dpi: int = 150):
    """A scalar field on the interface: flat-shaded facets with mesh edges and a colour bar.

    Args:
        points: (n_v, 3) vertex coordinates [mm] (or (n, 3) point coordinates).
        cells: (n_c, 3|4) facet vertex indices, or None for values at ``points``.
        values: (n_c,) per facet, or (n,) per point with ``cells=None``.
        label: colour-bar label (name and unit).
        title: axes title.
        cmap: matplotlib colour map (ParaView's default "Cool to Warm" is ``"coolwarm"``).
        clim: (min, max) of the colour scale; default the data range (the step's range).
        edges: draw the facet edges.
        axes: projection plane (module docstring).
        point_size: marker size for point values.
        ax: draw into these axes instead of a new figure.
        path: save a PNG there.
        figsize, dpi: of a new figure / the PNG.

    Returns:
        The figure.
    """
    p = _points(points)
    c = None if cells is None else _cells(cells, len(p))
    v = _values(values, len(p) if c is None else len(c),
                "values (one per point)" if c is None else "values (one per cell)")
    from matplotlib.colors import Normalize

    fig, ax = _new_figure(ax, figsize)
    p2, names = _plane(p, axes)
    if clim is not None:
        lo, hi = (float(c_) for c_ in clim)
    else:  # the data range, as ParaView's "Rescale to data range"
        lo, hi = (float(v.min()), float(v.max())) if v.size else (0.0, 1.0)
    if hi <= lo:  # a uniform field: a symmetric band around it keeps the colour bar readable
        pad = abs(lo) * 1e-6 or 1.0
        lo, hi = lo - pad, hi + pad
    mappable = _draw_map(ax, p2, c, v, cmap=cmap, norm=Normalize(lo, hi), edges=edges,
                         point_size=point_size)
    fig.colorbar(mappable, ax=ax, label=label)
    _frame(ax, names, title)
    return _finish(fig, path, dpi)


def plot_pressure_map(points, cells, pressure, *, label: str = "contact pressure p [MPa]",
                      **kwargs):
    """Contact pressure on the interface (see :func:`plot_facet_field` for the arguments)."""
    return plot_facet_field(points, cells, pressure, label=label, **kwargs)


def plot_status_map(points, cells, status, *, weights=None, title: str = "",
                    axes: str = "auto", edges: bool = True, point_size: float = 12.0,
                    ax: Any = None, path: Optional[str] = None, figsize=(6.0, 5.0),
                    dpi: int = 150):
    """Open / stick / slip map with the share of each state in the legend.

    Args:
        points, cells, axes, edges, point_size, ax, path, figsize, dpi: as
            :func:`plot_facet_field`.
        status: (n_c,) or (n,) integers 0 open, 1 stick, 2 slip.
        weights: (n_c,) or (n,) areas for the shares [mm^2]; default the facet areas
            (facets) or equal weights (points).
        title: axes title.

    Returns:
        The figure.
    """
    p = _points(points)
    c = None if cells is None else _cells(cells, len(p))
    n = len(p) if c is None else len(c)
    s = np.asarray(status)
    if s.shape != (n,) or (s.size and not np.isin(s, (0, 1, 2)).all()):
        raise ValueError(f"status of shape {s.shape} must be ({n},) with values 0 (open), "
                         f"1 (stick), 2 (slip); found {np.unique(s)[:6].tolist()}")
    if weights is None:
        if c is None:
            w = np.ones(n)
        else:  # facet areas from the (flat) facet polygons: fan of triangles from vertex 0
            x = p[c] if p.shape[1] == 3 else np.pad(p, ((0, 0), (0, 1)))[c]
            w = sum(0.5 * np.linalg.norm(np.cross(x[:, k] - x[:, 0], x[:, k + 1] - x[:, 0]),
                                         axis=1) for k in range(1, c.shape[1] - 1))
    else:
        w = _values(weights, n, "weights")
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    fig, ax = _new_figure(ax, figsize)
    p2, names = _plane(p, axes)
    cmap = ListedColormap(STATUS_COLORS)
    _draw_map(ax, p2, c, s.astype(float), cmap=cmap, norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3),
              edges=edges, point_size=point_size)
    total = float(np.sum(w)) or 1.0
    handles = [Patch(facecolor=STATUS_COLORS[k],
                     label=f"{STATUS_LABELS[k]} {100.0 * np.sum(w[s == k]) / total:.0f} %")
               for k in range(3)]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False,
              title="area")
    _frame(ax, names, title)
    return _finish(fig, path, dpi)


def plot_slip_quiver(points, vectors, *, cells=None, max_arrows: int = 400,
                     normalize: bool = True, scale: float = 1e3, label: str = "|slip| [um]",
                     title: str = "", axes: str = "auto", cmap: str = "viridis",
                     outline: bool = True, ax: Any = None, path: Optional[str] = None,
                     figsize=(6.0, 5.0), dpi: int = 150):
    """Arrows of a tangential vector field (slip, plastic slip, shear traction).

    Args:
        points: (n_v, 3) vertices with ``cells``, else (n, 3) arrow positions [mm].
        vectors: (n_c, 3) per facet (arrows at the facet centroids) or (n, 3) per point, in
            global components [mm]; only the components in the projection plane are drawn.
        cells: (n_c, 3|4) facet vertex indices, or None.
        max_arrows: at most about this many arrows (one per cell of a regular grid over the
            plot, so they stay readable on fine meshes).
        normalize: draw unit arrows (directions, as the paper's Figs 18-19) coloured by the
            magnitude; False draws arrows proportional to the vectors.
        scale: factor from the vectors' unit to the colour-bar unit (1e3: mm to um).
        label: colour-bar label.
        title, axes, cmap, ax, path, figsize, dpi: as :func:`plot_facet_field`.
        outline: draw the facet edges in light grey under the arrows.

    Returns:
        The figure.
    """
    p = _points(points)
    c = None if cells is None else _cells(cells, len(p))
    n = len(p) if c is None else len(c)
    vec = _values(vectors, n, "vectors", ncomp=-1)
    if int(max_arrows) < 1:
        raise ValueError(f"max_arrows = {max_arrows!r} must be >= 1")
    if vec.shape[1] == 2:
        vec = np.column_stack([vec, np.zeros(n)])
    at = p if c is None else p[c].mean(axis=1)
    if at.shape[1] == 2:
        at = np.column_stack([at, np.zeros(n)])
    fig, ax = _new_figure(ax, figsize)
    p3 = p if p.shape[1] == 3 else np.column_stack([p, np.zeros(len(p))])
    p2, names = _plane(p3, axes)
    pair = [("xyz".index(names[0])), ("xyz".index(names[1]))]
    xy, uv = at[:, pair], vec[:, pair]
    # thin out: one arrow per cell of a regular grid covering the plot
    if n > max_arrows:
        m = int(np.ceil(np.sqrt(max_arrows)))
        lo, span = xy.min(axis=0), np.maximum(np.ptp(xy, axis=0), 1e-300)
        ij = np.minimum((m * (xy - lo) / span).astype(int), m - 1)
        _, keep = np.unique(ij[:, 0] * m + ij[:, 1], return_index=True)
        xy, uv, vec = xy[keep], uv[keep], vec[keep]
    mag = np.linalg.norm(vec, axis=1) * scale
    if c is not None and outline:
        from matplotlib.collections import PolyCollection

        ax.add_collection(PolyCollection(p2[c], facecolors="none", edgecolors="#c8c8c8",
                                         linewidths=0.4))
    if normalize:
        length = np.linalg.norm(uv, axis=1)
        uv = np.where(length[:, None] > 0, uv / np.where(length > 0, length, 1.0)[:, None], 0.0)
        span = float(np.max(np.ptp(p2, axis=0))) if len(p2) else 1.0
        q = ax.quiver(xy[:, 0], xy[:, 1], uv[:, 0], uv[:, 1], mag, cmap=cmap, pivot="tail",
                      angles="xy", scale_units="xy",
                      scale=1.0 / (0.8 * span / np.sqrt(max(len(xy), 1))))
    else:
        q = ax.quiver(xy[:, 0], xy[:, 1], uv[:, 0], uv[:, 1], mag, cmap=cmap, pivot="tail",
                      angles="xy")
    fig.colorbar(q, ax=ax, label=label)
    ax.autoscale_view()
    _frame(ax, names, title)
    return _finish(fig, path, dpi)


# --------------------------------------------------------------------------------------------
# load paths
# --------------------------------------------------------------------------------------------
def plot_load_displacement(curves: Mapping[str, tuple], *, xlabel: str = "displacement [mm]",
                           ylabel: str = "force [N]", title: str = "", markers: bool = True,
                           ax: Any = None, path: Optional[str] = None, figsize=(6.0, 4.5),
                           dpi: int = 150):
    """Load-displacement curves.

    Args:
        curves: {label: (displacement (n,), force (n,))}, drawn in order.
        xlabel, ylabel, title: axis labels (with units) and title.
        markers: mark the increments.
        ax, path, figsize, dpi: as :func:`plot_facet_field`.

    Returns:
        The figure.
    """
    if not curves:
        raise ValueError("curves is empty: give at least one {label: (displacement, force)}")
    fig, ax = _new_figure(ax, figsize)
    for name, (u, f) in curves.items():
        u = np.asarray(u, dtype=float)
        f = _values(f, len(u), f"force of curve {name!r}")
        ax.plot(u, f, marker="o" if markers else None, ms=3, lw=1.2, label=name)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    if len(curves) > 1 or next(iter(curves)):
        ax.legend(frameon=False)
    if title:
        ax.set_title(title, fontsize=10)
    return _finish(fig, path, dpi)


def split_cycles(displacement: Sequence[float]) -> np.ndarray:
    """Cycle boundaries of a cyclic path: its start, every local minimum of the displacement
    (where it turns from decreasing to increasing), and its end.

    Args:
        displacement: (n,) displacement along the path.

    Returns:
        (n_cycles + 1,) increasing indices; cycle k spans ``[b[k], b[k + 1]]``.
    """
    u = np.asarray(displacement, dtype=float)
    if u.ndim != 1 or len(u) < 2:
        raise ValueError(f"displacement of shape {u.shape} must be 1D with >= 2 entries")
    du = np.diff(u)
    nonzero = np.flatnonzero(du)
    if nonzero.size == 0:
        return np.array([0, len(u) - 1])
    sign = np.sign(du[nonzero])
    # a turn from decreasing to increasing between two consecutive nonzero steps: the minimum
    # is the point after the last decreasing step
    minima = nonzero[np.flatnonzero((sign[:-1] < 0) & (sign[1:] > 0))] + 1
    return np.unique(np.r_[0, minima, len(u) - 1])


def plot_hysteresis(displacement, force, *, boundaries=None, cycles: Optional[Sequence[int]] = None,
                    energy_unit: str = "N mm", xlabel: str = "displacement [mm]",
                    ylabel: str = "force [N]", title: str = "", ax: Any = None,
                    path: Optional[str] = None, figsize=(6.0, 4.5), dpi: int = 150):
    """Force-displacement hysteresis loops, one colour per cycle, the energy of each cycle
    (:func:`loop_energies`) in the legend.

    Pass the cycles of the load program that made the path (``boundaries``, e.g.
    ``rough_contact.solver.program.cycle_boundaries``): a cycle that starts at zero
    displacement (0 -> +a -> -a -> 0) is one closed loop there, while :func:`split_cycles`
    cuts it at the minima into open pieces. A piece whose ends differ is drawn dashed, labelled
    "open path" and given no loop energy (its integral of F du is no loop area).

    Args:
        displacement: (n,) [mm].
        force: (n,) [N].
        boundaries: cycle boundaries (indices), cycle k spanning ``[b[k - 1], b[k]]``; default
            :func:`split_cycles`.
        cycles: the cycles to draw (1-based numbers of the boundaries' cycles); default all.
        energy_unit: unit of F du for the legend.
        xlabel, ylabel, title, ax, path, figsize, dpi: as :func:`plot_load_displacement`.

    Returns:
        The figure.
    """
    u = np.asarray(displacement, dtype=float)
    f = _values(force, len(u), "force")
    b = split_cycles(u) if boundaries is None else np.asarray(boundaries)
    energies = loop_energies(u, f, b)
    n = len(energies)
    chosen = range(1, n + 1) if cycles is None else [int(k) for k in cycles]
    bad = [k for k in chosen if not 1 <= k <= n]
    if bad or not chosen:
        raise ValueError(f"cycles {list(chosen)} are invalid: the path has cycles 1 .. {n}")
    closed_tol = 1e-9 * max(float(np.ptp(u)), 1e-300)
    fig, ax = _new_figure(ax, figsize)
    for k in chosen:
        seg = slice(b[k - 1], b[k] + 1)
        if abs(u[b[k]] - u[b[k - 1]]) <= closed_tol:
            ax.plot(u[seg], f[seg], marker="o", ms=2.5, lw=1.2,
                    label=f"cycle {k}: $\\oint F\\,du$ = {energies[k - 1]:.4g} {energy_unit}")
        else:
            ax.plot(u[seg], f[seg], ls="--", color="0.55", marker="o", ms=2.0, lw=1.0,
                    label=f"part {k}: open path (not a loop)")
    ax.axhline(0.0, color="0.6", lw=0.5)
    ax.axvline(0.0, color="0.6", lw=0.5)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.legend(frameon=False, fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    return _finish(fig, path, dpi)


def plot_fretting_map(amplitude, energy_ratio, slip_fraction, *, references: Optional[Mapping[
                      str, tuple]] = None, transition: Optional[float] = None,
                      xlabel: str = "displacement amplitude $\\delta^*$ [um]",
                      title: str = "", path: Optional[str] = None, figsize=(10.0, 4.2),
                      dpi: int = 150):
    """A fretting-map view of an amplitude sweep: the energy ratio A = E_d / (4 F* delta*) and
    the slipping share of the contact area against the displacement amplitude (log axis), with
    the partial-to-gross slip transition marked.

    Args:
        amplitude: (n,) displacement amplitudes, > 0 (unit in ``xlabel``).
        energy_ratio: (n,) A [-].
        slip_fraction: (n,) slipping area / contact area in [0, 1] [-].
        references: {label: (amplitude (m,), A (m,)[, fmt])} drawn on the A panel (dashed,
            or in the matplotlib format ``fmt``, e.g. ``"x"`` for values at the amplitudes).
        transition: amplitude of the partial-to-gross slip transition (a vertical line), or None.
        xlabel, title, path, figsize, dpi: as :func:`plot_load_displacement`.

    Returns:
        The figure (two axes).
    """
    a = np.asarray(amplitude, dtype=float)
    if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a) & (a > 0)):
        raise ValueError(f"amplitude {a.tolist()} must be a non-empty 1D array of finite "
                         "values > 0")
    ratio = _values(energy_ratio, len(a), "energy_ratio")
    slip = _values(slip_fraction, len(a), "slip_fraction")
    if np.any((slip < 0) | (slip > 1 + 1e-12)):
        raise ValueError(f"slip_fraction {slip.tolist()} must lie in [0, 1]")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    ax0, ax1 = fig.subplots(1, 2)
    ax0.semilogx(a, ratio, "o-", color="C0", label="computed")
    for name, (x, y, *fmt) in (references or {}).items():
        ax0.semilogx(np.asarray(x, dtype=float), _values(y, len(x), f"reference {name!r}"),
                     fmt[0] if fmt else "--", lw=1.0, label=name)
    ax0.set_ylabel("energy ratio $A = E_d / (4 F^* \\delta^*)$ [-]")
    ax0.set_ylim(-0.02, 1.02)
    ax1.semilogx(a, 100.0 * slip, "s-", color="C3")
    ax1.set_ylabel("slipping share of the contact area [%]")
    ax1.set_ylim(-2, 102)
    for ax in (ax0, ax1):
        if transition is not None:
            ax.axvline(transition, color="0.4", lw=0.8, ls=":")
            ax.text(transition, 0.50, " gross slip ->", transform=ax.get_xaxis_transform(),
                    fontsize=7, va="bottom", color="0.3")
            ax.text(transition, 0.44, "<- partial slip ", transform=ax.get_xaxis_transform(),
                    fontsize=7, va="top", ha="right", color="0.3")
        ax.set_xlabel(xlabel)
        ax.grid(True, which="both", lw=0.3)
        ax.set_xticks(a)                       # the amplitudes run, in plain numbers
        ax.set_xticklabels([f"{v:g}" for v in a], rotation=60, fontsize=8)
        ax.minorticks_off()
    ax0.legend(frameon=False, fontsize=7, loc="upper left")
    if title:
        fig.suptitle(title, fontsize=10)
    return _finish(fig, path, dpi)
