"""rough_contact: 3D frictional contact across rough interfaces for FEniCSx (DOLFINx 0.5.2).

Model: R. Buczkowski and M. Kleiber, "Statistical Models of Rough Surfaces for Finite Element
3D-Contact Analysis", Arch Comput Methods Eng 16 (2009) 399-424.

Layers (each imports only those above it in this list):
    validation                        check_scalar, the one input check of every layer
    surface                           what a rough surface is: moments, spectra, height maps
    micro                             asperity, summit population, normal-law tables, BEM law
    interface                         pure numpy interface laws at quadrature points, the
                                      enforcement strategies, the interface history
    cycles, references                loop energies; closed forms the tests compare with
    fem                               DOLFINx: pairings, jump operator, ContactInterface,
                                      ContactProblem (the only package importing dolfinx,
                                      with io and the gmsh mesh builders)
    solver                            PETSc SNES, load stepping over the interface lifecycle,
                                      checkpoints, load programs (petsc4py, no dolfinx)
    io                                results on disk (XDMF, CSV, atomic writes) and plots
    scenes                            the paper's and the verification scenes (typed results)

Internal unit system: mm, N, MPa (N/mm^2), so stiffnesses per area are in MPa/mm = N/mm^3.
Spectral moments are given in the paper's micrometre convention at the API boundary
(see rough_contact.surface).
"""

__version__ = "0.1.0"
