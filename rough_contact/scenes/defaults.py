"""Defaults shared by the scenes, in one place, with their units and the reason for each value.

These are numerical settings of the scenes, not parameters of the paper (those stay with the
scene that reproduces it, e.g. ``flat_punch.E``). A scene passes them on explicitly; changing
one here changes every scene that uses it, so each entry names its users.

Units: mm, N, MPa (stiffnesses per area in MPa/mm).
"""

from __future__ import annotations

__all__ = ["SEATING_STIFFNESS", "INDENTER_PENALTY", "GRAIN_X", "quadrature_degree"]

SEATING_STIFFNESS: float = 1e3
"""Seating spring on the first contact surface [MPa/mm] (``ContactProblem(seating_stiffness=)``).

A body held only by the rough interface (the punch, the upper fretting block, the bolt head)
has a singular first Jacobian while no interface point carries pressure. The spring is added
to the Jacobian only, and only while no point is in contact; the residual never sees it, so it
does not change a converged result — only the first Newton steps. Users: ``flat_punch``,
``beam``, ``fretting``, ``bolt_head`` (and the FE tests that build the same set-ups)."""

INDENTER_PENALTY: float = 1e8
"""Normal penalty of the smooth indentation scenes checked against closed forms [MPa/mm].

Stiff compared with the block's E / h (E = 200 GPa, h ~ 0.04-0.2 mm at the contact), so the
penetration is small against the 4 um indentation; its effect on the Hertz radius and peak
pressure is measured in ``docs/indenters.md`` and ``docs/mindlin.md``. Users: ``hertz``
(``run``, ``run_elastic``), ``mindlin``."""

GRAIN_X: tuple = (1.0, 0.0, 0.0)
"""Grinding direction of the rough surface (local x of the orthotropic friction law) [-]: the
global x axis, as for the paper's punch (Fig 18). Users: ``flat_punch``, ``bolt_head``,
``hertz``, ``mindlin`` (the beam uses its own axis, ``beam.GRAIN``)."""


def quadrature_degree(order: int) -> int:
    """Default degree of the interface (facet) quadrature for Lagrange elements of ``order``:
    2 ``order`` (exact for the product of two shape functions on a flat facet). Used by every
    scene unless a degree is given."""
    return 2 * int(order)
