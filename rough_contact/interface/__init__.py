"""Pure-numpy interface laws evaluated at facet quadrature points (no dolfinx import)."""
