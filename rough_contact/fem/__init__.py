"""DOLFINx layer: meshes from gmsh, the contact interface operator, bulk problem (imports dolfinx)."""
