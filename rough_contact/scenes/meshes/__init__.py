"""gmsh builders for the paper's scenes: flat punch on a foundation, beam on a rigid base, blocks."""
