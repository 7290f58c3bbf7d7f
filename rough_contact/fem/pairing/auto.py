"""``"auto"``: the conforming pairing when the two surfaces match facet to facet, else a
non-matching one (the projection for ``ContactInterface(pairing="auto")``; the scenes default to
the mortar, the one that passes the patch test).

Units: mm.
"""

from __future__ import annotations

from typing import Optional

from rough_contact.fem.pairing.base import PairedPoints, Pairing, SurfaceContext
from rough_contact.fem.pairing.conforming import ConformingPairing
from rough_contact.fem.pairing.mortar import MortarPairing
from rough_contact.fem.pairing.projection import ProjectionPairing

__all__ = ["AutoPairing"]

NONMATCHING = ("projection", "mortar")


class AutoPairing:
    """Conforming if every first facet finds its matching facet, else ``nonmatching``.

    Args:
        second_tag: facet tag of the second surface.
        nonmatching: ``"projection"``, ``"mortar"`` (needs the Gauss rule), or None: surfaces
            that do not match are an error naming the choices.
        match_tolerance: conforming vertex matching tolerance relative to the facet size, > 0.
        search_radius: of the non-matching pairing [mm] (None: its default).

    Attributes:
        chosen: the pairing used by the last :meth:`pair` (None before).
    """

    def __init__(self, second_tag: int, nonmatching: Optional[str] = "projection",
                 match_tolerance: float = 1e-6, search_radius: Optional[float] = None):
        if nonmatching not in NONMATCHING + (None,):
            raise ValueError(f"nonmatching = {nonmatching!r} is invalid: it must be "
                             "'projection', 'mortar' or None")
        self.second_tag, self.nonmatching = second_tag, nonmatching
        self.conforming = ConformingPairing(second_tag, match_tolerance, strict=False)
        self.search_radius = search_radius
        self.chosen: Optional[Pairing] = None

    def describe(self) -> dict:
        """Its options (``rough_contact.fingerprint.Describable``): what a checkpoint records
        (the pairing it chose is recorded beside, by the interface)."""
        return dict(second_tag=int(self.second_tag), nonmatching=self.nonmatching,
                    match_tolerance=float(self.conforming.match_tolerance),
                    search_radius=self.search_radius)

    def pair(self, ctx: SurfaceContext) -> PairedPoints:
        """The conforming points, or the non-matching pairing's (collective).

        Raises:
            ValueError (every rank): the surfaces do not match and ``nonmatching`` is None, or
                the non-matching pairing's own errors (prefixed with what was tried).
        """
        paired = self.conforming.pair(ctx)
        if paired is not None:
            self.chosen = self.conforming
            return paired
        what = (f"pairing = 'auto': surfaces {ctx.first_tag} and {self.second_tag} do not match "
                "facet to facet")
        if self.nonmatching is None:
            raise ValueError(
                f"{what}; choose a non-matching pairing: pairing='mortar' (passes the patch "
                "test; needs quadrature='gauss') or pairing='projection' (cheaper, fails the "
                "patch test on non-nested meshes: docs/nonmatching.md)")
        pairing = (MortarPairing if self.nonmatching == "mortar" else ProjectionPairing)(
            self.second_tag, self.search_radius)
        try:
            paired = pairing.pair(ctx)
        except ValueError as exc:       # raised on every rank together (collective checks)
            raise ValueError(f"{what}, so the {self.nonmatching} pairing was tried: "
                             f"{exc}") from exc
        self.chosen = pairing
        return paired
