"""Pairings: how the interface points of the first surface find their partners.

One module per pairing, all behind :class:`~rough_contact.fem.pairing.base.Pairing`
(``pair(ctx) -> PairedPoints``); :class:`~rough_contact.fem.pairing.base.SlidingPairing` is the
optional capability of following large motions:

* :mod:`.conforming` — the same surface mesh on both sides, facet to facet (exact);
* :mod:`.projection` — non-matching meshes, Gauss points projected along the normal;
  ``SlidingProjectionPairing`` re-pairs on the deformed surfaces at every increment;
* :mod:`.mortar` — non-matching meshes, segment-to-segment integration (passes the patch test);
* :mod:`.rigid` — a rigid counter-surface;
* :mod:`.auto` — conforming when the surfaces match facet to facet, else a non-matching one;
* :mod:`.facets`, :mod:`.geometry` — facet rules and geometry, the projection and clipping
  kernels the pairings share.
"""

from rough_contact.fem.pairing.base import (PairedPoints, Pairing, Partners, SlidingPairing,
                                            SurfaceContext)
from rough_contact.fem.pairing.conforming import ConformingPairing
from rough_contact.fem.pairing.mortar import MortarPairing
from rough_contact.fem.pairing.projection import ProjectionPairing, SlidingProjectionPairing
from rough_contact.fem.pairing.rigid import RigidPairing
from rough_contact.fem.pairing.auto import AutoPairing  # noqa: E402 (uses the ones above)

__all__ = ["PairedPoints", "Pairing", "Partners", "SlidingPairing", "SurfaceContext",
           "ConformingPairing", "ProjectionPairing", "SlidingProjectionPairing", "MortarPairing",
           "RigidPairing", "AutoPairing"]
