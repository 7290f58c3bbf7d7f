"""ContactInterface: UFL oracle, finite-difference Jacobian, patch test, empty ranks.

Run serial and in parallel (results must not depend on the number of ranks):
    .venv/bin/python -m pytest tests/fem/test_contact.py
    mpirun -n 2 .venv/bin/python -m mpi4py -m pytest tests/fem/test_contact.py
"""

from __future__ import annotations

import numpy as np
import pytest
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
from dolfinx import fem
from dolfinx import mesh as dmesh
from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.interface.contract import ConvergenceError
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from rough_contact.scenes.meshes import blocks

LOWER_TOP, UPPER_BOTTOM, LOWER_BOTTOM, UPPER_TOP = 1, 2, 3, 4
KUHN = np.array(
    [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]]
)


def _box_tets(n, lo, hi, offset):
    """Nodes and Kuhn tetrahedra of a structured box (conforming diagonals)."""
    nx, ny, nz = n
    ax = [np.linspace(lo[d], hi[d], n[d] + 1) for d in range(3)]
    X = np.stack(np.meshgrid(*ax, indexing="ij"), axis=-1).reshape(-1, 3)
    idx = np.arange(X.shape[0]).reshape(nx + 1, ny + 1, nz + 1)
    corners = np.stack(
        [idx[i : i + nx, j : j + ny, k : k + nz] for k in (0, 1) for j in (0, 1) for i in (0, 1)],
        axis=-1,
    ).reshape(-1, 8)
    return X, corners[:, KUHN].reshape(-1, 4) + offset


def two_blocks(comm, n=(3, 3, 2), size=(1.0, 1.0, 0.5), single=False, split=False):
    """Two stacked boxes [0,Lx]x[0,Ly]x[-H,0] and [0,Lx]x[0,Ly]x[0,H] with duplicated nodes at z=0.

    With ``single`` only the lower box; with ``split`` the lower box goes to rank 0 and the
    upper one to the last rank (every contact partner on another rank). Facet tags: 1 lower
    top, 2 upper bottom, 3 lower bottom, 4 upper top.
    """
    Lx, Ly, H = size
    if comm.rank == 0:
        X1, T1 = _box_tets(n, (0, 0, -H), (Lx, Ly, 0), 0)
        X, T = X1, T1
        if not single:
            X2, T2 = _box_tets(n, (0, 0, 0), (Lx, Ly, H), X1.shape[0])
            X, T = np.vstack([X1, X2]), np.vstack([T1, T2])
    else:
        X, T = np.zeros((0, 3)), np.zeros((0, 4), dtype=np.int64)
    if split:
        def destinations(n_cells, nparts):
            half = n_cells // 2  # lower cells first, then upper ones
            return np.where(np.arange(n_cells) < half, 0, nparts - 1)

        msh = compat.create_mesh(comm, T, X, "tetrahedron", 1, destinations=destinations)
    else:
        msh = compat.create_mesh(comm, T, X, "tetrahedron", 1)
    tdim = 3
    msh.topology.create_connectivity(tdim - 1, tdim)
    bfacets = dmesh.exterior_facet_indices(msh.topology)
    mid = dmesh.compute_midpoints(msh, tdim - 1, bfacets)
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    cells = np.array([f_to_c.links(f)[0] for f in bfacets], dtype=np.int32)
    cmid = dmesh.compute_midpoints(msh, tdim, cells)
    tol = 1e-10
    values = np.zeros(bfacets.size, dtype=np.int32)
    values[(np.abs(mid[:, 2]) < tol) & (cmid[:, 2] < 0)] = LOWER_TOP
    values[(np.abs(mid[:, 2]) < tol) & (cmid[:, 2] > 0)] = UPPER_BOTTOM
    values[np.abs(mid[:, 2] + H) < tol] = LOWER_BOTTOM
    values[np.abs(mid[:, 2] - H) < tol] = UPPER_TOP
    keep = values > 0
    tags = dmesh.meshtags(msh, tdim - 1, bfacets[keep], values[keep])
    return msh, tags


def upper_cells(msh):
    """Local cells (owned and ghost) of the upper body."""
    n = msh.topology.index_map(3).size_local + msh.topology.index_map(3).num_ghosts
    cells = np.arange(n, dtype=np.int32)
    return cells[dmesh.compute_midpoints(msh, 3, cells)[:, 2] > 0]


def interpolate_bodies(u, f):
    """u = f(x, 0) on the lower body and f(x, 1) on the upper one (duplicated interface nodes)."""
    msh = u.function_space.mesh
    up = upper_cells(msh)
    n = msh.topology.index_map(3).size_local + msh.topology.index_map(3).num_ghosts
    low = np.setdiff1d(np.arange(n, dtype=np.int32), up)
    compat.interpolate(u, lambda x: f(x, 0.0), cells=low)
    compat.interpolate(u, lambda x: f(x, 1.0), cells=up)
    u.x.scatter_forward()


def smooth_field(x, up=0.0, scale=1e-3):
    """A fixed smooth displacement field, different on each body (jump across z=0)."""
    return scale * np.stack(
        [
            np.sin(2 * x[0] + 1) * np.cos(x[1]) + 0.5 * up * np.cos(3 * x[1]),
            np.cos(x[0] - 2 * x[1]) - 0.3 * up * np.sin(x[0]),
            np.sin(x[0] + x[1] + x[2]) - 0.8 * up * (1 + x[0] * x[1]),
        ]
    )


def vec_copy(V, u):
    return compat.petsc_vector(u).copy()


def residual(ci, V, x):
    b = compat.create_petsc_vector(V)
    b.set(0.0)
    ci.evaluate(x)
    ci.assemble_residual(b)
    return b


@pytest.mark.parametrize("degree", [1, 2])
def test_against_ufl_linear_penalty_rigid(degree):
    """(a) Frictionless linear penalty against a rigid plane == k (u.n)(v.n) ds in UFL."""
    comm = MPI.COMM_WORLD
    msh, tags = two_blocks(comm, n=(3, 2, 2), single=True)
    V = compat.vector_space(msh, degree)
    k = 1.7e3
    ci = ContactInterface(V, tags, LOWER_TOP, law=LinearPenalty(k), quadrature_degree=2 * degree)
    _assert_is_ufl_penalty(ci, V, k, ufl.Measure("ds", domain=msh, subdomain_data=tags)(LOWER_TOP))
    np.testing.assert_allclose(ci.nominal_area(), 1.0, rtol=1e-13)


def _assert_is_ufl_penalty(ci, V, k, ds):
    """At a smooth field, the residual and Jacobian of ``ci`` are those of the UFL form
    k (u.n)(v.n) ``ds`` (to 1e-12; ``ds``: the measure of the contact face)."""
    u = fem.Function(V)
    u.interpolate(smooth_field)
    v, du = ufl.TestFunction(V), ufl.TrialFunction(V)
    n = ufl.FacetNormal(V.mesh)
    F = fem.form(k * ufl.inner(u, n) * ufl.inner(v, n) * ds)
    a = fem.form(k * ufl.inner(du, n) * ufl.inner(v, n) * ds)
    b_ufl = dolfinx.fem.petsc.assemble_vector(F)
    b_ufl.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
    b_ci = residual(ci, V, u)
    scale = b_ufl.norm()
    assert scale > 0
    b_ci.axpy(-1.0, b_ufl)
    assert b_ci.norm() <= 1e-12 * scale

    A_ufl = dolfinx.fem.petsc.assemble_matrix(a)
    A_ufl.assemble()
    A_ci = ci.create_matrix(a)
    ci.evaluate(u)
    ci.assemble_jacobian(A_ci)
    A_ci.assemble()
    nrm = A_ufl.norm()
    A_ci.axpy(-1.0, A_ufl, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    assert A_ci.norm() <= 1e-12 * nrm


def test_create_matrix_holds_bulk_and_interface():
    """The merged pattern takes dolfinx's own bulk assembly (bcs included) unchanged."""
    comm = MPI.COMM_WORLD
    msh, tags = two_blocks(comm, n=(2, 2, 2))
    V = compat.vector_space(msh, 2)
    du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = fem.form(ufl.inner(ufl.grad(du), ufl.grad(v)) * ufl.dx)
    dofs = fem.locate_dofs_topological(V, 2, tags.indices[tags.values == LOWER_BOTTOM])
    bc = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), dofs, V)
    law = SoftplusPenalty(1e3, 1e-3, k_tangential=5e2, friction=0.3)
    ci = ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, bcs=[bc])
    A_ref = dolfinx.fem.petsc.assemble_matrix(a, bcs=[bc])
    A_ref.assemble()
    A = ci.create_matrix(a)
    dolfinx.fem.petsc.assemble_matrix(A, a, bcs=[bc])
    A.assemble()
    A.axpy(-1.0, A_ref, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    assert A.norm() <= 1e-13 * A_ref.norm()
    # interface entries go in without new allocations (the option makes PETSc raise if not)
    A.zeroEntries()
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, 1e-2))
    dolfinx.fem.petsc.assemble_matrix(A, a, bcs=[bc])
    ci.evaluate(u)
    ci.assemble_jacobian(A)
    A.assemble()
    assert A.norm() > A_ref.norm()


def fd_check(ci, V, x, eps, rng):
    """Central FD of the interface residual along random directions against J * direction."""
    A = ci.create_matrix(fem.form(ufl.inner(ufl.TrialFunction(V), ufl.TestFunction(V)) * ufl.dx))
    ci.evaluate(x)
    ci.assemble_jacobian(A)
    A.assemble()
    errs = []
    for _ in range(3):
        d = x.duplicate()
        r0, r1 = d.getOwnershipRange()
        d.setArray(rng.uniform(-1, 1, 3 * V.dofmap.index_map.size_global)[r0:r1])
        xp, xm = x.copy(), x.copy()
        xp.axpy(eps, d)
        xm.axpy(-eps, d)
        fd = residual(ci, V, xp)
        fd.axpy(-1.0, residual(ci, V, xm))
        fd.scale(1.0 / (2 * eps))
        Jd = x.duplicate()
        A.mult(d, Jd)
        Jd.axpy(-1.0, fd)
        errs.append(Jd.norm() / fd.norm())
    return max(errs)


@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("regime", ["penalty", "stick", "slip"])
def test_jacobian_finite_difference_two_blocks(degree, regime):
    """(b) The interface Jacobian equals a central FD of the interface residual."""
    comm = MPI.COMM_WORLD
    msh, tags = two_blocks(comm, n=(2, 3, 1))
    V = compat.vector_space(msh, degree)
    if regime == "penalty":
        law = LinearPenalty(2e3, k_tangential=7e2)
        scale = 1e-3
    else:
        mu = 0.3 if regime == "stick" else 0.05
        law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=mu)
        scale = 1e-6 if regime == "stick" else 2e-3
    ci = ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, grain_direction=(1, 1, 0))
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, scale))
    x = vec_copy(V, u)
    res = ci.evaluate(x)
    n_slip = comm.allreduce(int(res.slipping.sum()))
    if regime == "stick":
        assert n_slip == 0
    if regime == "slip":
        assert n_slip > ci.n_points_global // 2
    rng = np.random.default_rng(3)
    assert fd_check(ci, V, x, 1e-9 * scale / 1e-3, rng) < 1e-6


def test_uniform_jump_patch():
    """(c) A uniform relative displacement gives force = k * jump * area, exactly."""
    comm = MPI.COMM_WORLD
    Lx, Ly = 1.3, 0.7
    msh, tags = two_blocks(comm, n=(3, 2, 1), size=(Lx, Ly, 0.4))
    V = compat.vector_space(msh, 2)
    kn, kt = 3e3, 1e3
    ci = ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=LinearPenalty(kn, kt))
    d = np.array([2e-3, -1e-3, -5e-4])  # upper body moves by d, lower stays
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: np.outer(d * up, np.ones(x.shape[1])))
    ci.evaluate(u)
    area = Lx * Ly
    # first surface = lower top: n = +z, x = grain = global x, y = n x x = global y
    t = np.array([kt * d[0], kt * d[1], kn * d[2]])
    np.testing.assert_allclose(ci.contact_force(), t * area, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(ci.nominal_area(), area, rtol=1e-13)
    np.testing.assert_allclose(ci.real_contact_area(), area, rtol=1e-13)
    # the residual transmits -force to the second body and +force to the first (sum of nodal
    # residuals per component over each body, partition of unity)
    b = residual(ci, V, u)
    r0, r1 = b.getOwnershipRange()
    n_own = V.dofmap.index_map.size_local
    up_nodes = np.unique(compat.cell_dofmap(V)[upper_cells(msh)].ravel())
    upper = np.zeros(n_own, dtype=bool)
    upper[up_nodes[up_nodes < n_own]] = True
    upper = np.repeat(upper, 3)
    arr = b.getArray().reshape(-1)
    comp = np.tile(np.arange(3), n_own)
    on_upper = comm.allreduce(np.bincount(comp[upper], arr[upper], minlength=3))
    on_lower = comm.allreduce(np.bincount(comp[~upper], arr[~upper], minlength=3))
    np.testing.assert_allclose(on_upper, t * area, rtol=1e-12)
    np.testing.assert_allclose(on_lower, -t * area, rtol=1e-12)
    st = ci.summary()
    assert st.n_points == ci.n_points_global and st.n_contact == st.n_points  # d_z < 0: closed
    assert ci.n_contact() == st.n_points
    np.testing.assert_allclose(st.max_slip, np.hypot(d[0], d[1]), rtol=1e-12)
    np.testing.assert_allclose(st.contact_force, t * area, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose([st.nominal_area, st.real_area, st.contact_area],
                               [area, area, area], rtol=1e-13)
    assert st.n_slipping == 0 and st.slipping_area == 0.0 and st.dissipation == 0.0


def _coulomb_assembled(V, tags, bcs=()):
    """A softplus Coulomb interface between the blocks (with ``bcs``), its residual and its
    assembled Jacobian (in the bulk pattern) at a smooth field: (interface, b, A)."""
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.3)
    ci = ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, bcs=bcs)
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, 2e-3))
    b = residual(ci, V, u)
    A = ci.create_matrix(fem.form(ufl.inner(ufl.TrialFunction(V), ufl.TestFunction(V)) * ufl.dx))
    ci.evaluate(u)
    ci.assemble_jacobian(A)
    A.assemble()
    return ci, b, A


def _global_figures(comm, degree, patch):
    msh, tags = two_blocks(comm, n=(4, 3, 1))
    if patch:  # keep only a small patch of the interface tagged: most ranks own none of it
        mid = dmesh.compute_midpoints(msh, 2, tags.indices)
        small = (mid[:, 0] < 0.3) & (mid[:, 1] < 0.4)
        vals = np.where(
            np.isin(tags.values, [LOWER_TOP, UPPER_BOTTOM]) & ~small, 99, tags.values
        ).astype(np.int32)
        tags = dmesh.meshtags(msh, 2, tags.indices, vals)
    V = compat.vector_space(msh, degree)
    ci, b, A = _coulomb_assembled(V, tags)
    ci.commit()
    st = ci.summary()
    return (
        ci.n_points, np.concatenate([
            ci.contact_force(), [ci.real_contact_area(), ci.nominal_area(), ci.dissipation(),
                                 b.norm(), A.norm(), st.n_contact, st.n_slipping, st.max_slip]
        ]),
    )


@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("patch", [False, True])
def test_rank_independent_and_empty_ranks(degree, patch):
    """(d) Same global figures on COMM_WORLD as on one rank; ranks owning no facet work."""
    n_local, world = _global_figures(MPI.COMM_WORLD, degree, patch)
    _, serial = _global_figures(MPI.COMM_SELF, degree, patch)
    np.testing.assert_allclose(world, serial, rtol=1e-10, atol=1e-14)
    if patch and MPI.COMM_WORLD.size > 1:
        # the patch is small: at least one rank should own none of it (the test's purpose)
        assert MPI.COMM_WORLD.allreduce(n_local == 0, op=MPI.LOR)


def test_errors():
    comm = MPI.COMM_WORLD
    msh, tags = two_blocks(comm, n=(2, 2, 1))
    V = compat.vector_space(msh, 1)
    law = LinearPenalty(1.0)
    with pytest.raises(ValueError, match="tag 42"):
        ContactInterface(V, tags, 42, UPPER_BOTTOM, law=law)
    with pytest.raises(ValueError, match="no matching facet"):  # top vs bottom: far apart
        ContactInterface(V, tags, LOWER_TOP, UPPER_TOP, law=law, pairing="conforming")
    # the same with the default pairing: the projection finds the upper top 0.5 mm away, facing
    # the same way as the lower top: a wrong tag, said so
    with pytest.raises(ValueError, match=r"24 of 24 quadrature points .* no partner .* face the "
                       r"same way .* 0.5 mm away"):
        ContactInterface(V, tags, LOWER_TOP, UPPER_TOP, law=law)
    with pytest.raises(ValueError, match="pairing = 'segment' is invalid"):
        ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, pairing="segment")
    with pytest.raises(ValueError, match="search_radius = -1.0 mm is invalid"):
        ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, search_radius=-1.0)
    with pytest.raises(ValueError, match="grain_direction"):
        ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, grain_direction=(0, 0, 1))
    with pytest.raises(ValueError, match="quadrature_degree = 1.5 is invalid"):
        ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, quadrature_degree=1.5)
    with pytest.raises(ValueError, match="quadrature_degree = -1 is invalid"):
        ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, quadrature_degree=-1)
    with pytest.raises(ValueError, match="match_tolerance = 0.0 is invalid"):
        ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, match_tolerance=0.0)
    with pytest.raises(ValueError, match="rigid_plane"):
        ContactInterface(V, tags, LOWER_TOP, law=law, rigid_plane=(0.0, 0.0, 1.0))

    class NaNLaw:
        def initial_state(self, n):
            return law.initial_state(n)

        def evaluate(self, jump, committed):
            r = law.evaluate(jump, committed)
            r.traction[:2] = np.nan
            return r

    ci = ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=NaNLaw())
    # a convergence failure on every rank (also on a rank whose own points are all finite)
    with pytest.raises(ConvergenceError, match="non-finite traction"):
        ci.evaluate(fem.Function(V))


class _ExponentialNormal:
    """p = p0 exp(-h / l): a smooth normal law that never opens (k = p / l)."""

    def evaluate(self, h, curvature=False):
        p = 5.0 * np.exp(-np.asarray(h, float) / 1e-3)
        out = (p, p / 1e-3, p / (p + 1.0))
        return out + (-p / 1e-6,) if curvature else out


@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("regime", ["stick", "slip"])
def test_jacobian_finite_difference_rough_law(degree, regime):
    """(b) FD Jacobian with the project's friction law (orthotropic slip hardening)."""
    from rough_contact.interface import law as law_mod
    from rough_contact.interface.friction import OrthotropicSlipHardening
    from rough_contact.interface.tangential import TangentialStiffness

    friction = OrthotropicSlipHardening(
        (0.3, 0.5), (0.5, 0.7), (275.0, 100.0), potential_axes=(0.125, 0.2)
    )
    law = law_mod.InterfaceLaw(
        _ExponentialNormal(), TangentialStiffness((0.7, 1.0)), friction, h0=1e-3
    )
    comm = MPI.COMM_WORLD
    msh, tags = two_blocks(comm, n=(2, 2, 1))
    V = compat.vector_space(msh, degree)
    ci = ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, grain_direction=(1, 0.5, 0))
    scale = 1e-7 if regime == "stick" else 3e-3
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, scale))
    x = compat.petsc_vector(u).copy()
    res = ci.evaluate(x)
    frac = comm.allreduce(int(res.slipping.sum())) / ci.n_points_global
    print("slipping fraction", frac)
    assert frac == 0.0 if regime == "stick" else frac > 0.9
    assert comm.allreduce(int(res.contact.sum())) == ci.n_points_global
    # step 1e-8 mm: small against the law's length scales (1e-3 mm, stick limit ~2e-4 mm)
    assert fd_check(ci, V, x, 1e-8, np.random.default_rng(5)) < 1e-6


# ---- scenes from rough_contact/scenes/meshes (gmsh): P2 geometry and hexahedra ----------------
GMSH_CASES = [("tetrahedron", 1), ("tetrahedron", 2), ("hexahedron", 1), ("hexahedron", 2)]


@pytest.mark.parametrize("cell_type,order", GMSH_CASES)
def test_uniform_jump_patch_gmsh_scene(cell_type, order):
    """(c) on the gmsh two_blocks scene (curved-capable P2 geometry, hexahedra):
    force = -k d area."""
    lx, ly = 1.0, 0.8
    sc = blocks.two_blocks(lx=lx, ly=ly, h1=0.4, h2=0.4, mesh_size=0.35, order=order,
                           cell_type=cell_type)
    V = compat.vector_space(sc.mesh, order)
    kn, kt = 3e3, 1e3
    first, second = sc.contact_pair  # first = upper block bottom: n = -z
    ci = ContactInterface(V, sc.facet_tags, first, second, law=LinearPenalty(kn, kt),
                          quadrature_degree=2 * order)
    d = np.array([2e-3, -1e-3, -5e-4])
    u = fem.Function(V)
    upper = sc.cell_tags.find(sc.tag("upper"))
    compat.interpolate(u, lambda x: np.outer(d, np.ones(x.shape[1])), cells=upper)
    ci.evaluate(u)
    # the upper body moved by d relative to the lower one: the springs pull it back
    np.testing.assert_allclose(ci.contact_force(), -np.array([kt, kt, kn]) * d * lx * ly,
                               rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(ci.nominal_area(), lx * ly, rtol=1e-12)


@pytest.mark.parametrize("cell_type,order", GMSH_CASES)
def test_against_ufl_gmsh_block_on_plane(cell_type, order):
    """(a) on the gmsh block_on_plane scene with its rigid plane: same vector and matrix as
    UFL."""
    sc = blocks.block_on_plane(lx=1.0, ly=0.7, h=0.5, mesh_size=0.3, order=order,
                               cell_type=cell_type)
    V = compat.vector_space(sc.mesh, order)
    k = 2.3e3
    first, _ = sc.contact_pair
    ci = ContactInterface(V, sc.facet_tags, first, None, law=LinearPenalty(k),
                          rigid_plane=sc.rigid_plane, quadrature_degree=2 * order + 1)
    ds = ufl.Measure("ds", domain=sc.mesh, subdomain_data=sc.facet_tags,
                     metadata={"quadrature_degree": 2 * order + 1})
    _assert_is_ufl_penalty(ci, V, k, ds(first))


def _partner_figures(c, split, degree, pairing):
    msh, tags = two_blocks(c, n=(3, 2, 1), split=split)
    V = compat.vector_space(msh, degree)
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.2)
    ci = ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, pairing=pairing)
    assert ci.pairing_used == pairing
    if split and c.size > 1:
        # all partners live elsewhere (every group is a facet with its one partner)
        assert ci.n_remote_partners == ci.n_facets == ci.n_groups
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, 2e-3))
    b = residual(ci, V, u)
    mass = fem.form(ufl.inner(ufl.TrialFunction(V), ufl.TestFunction(V)) * ufl.dx)
    A = ci.create_matrix(mass)
    ci.evaluate(u)
    ci.assemble_jacobian(A)
    A.assemble()
    figs = np.concatenate([ci.contact_force(), [b.norm(), A.norm(), ci.real_contact_area()]])
    if split:
        assert fd_check(ci, V, compat.petsc_vector(u).copy(), 1e-8, np.random.default_rng(9)) < 1e-6
    return figs


@pytest.mark.parametrize("pairing", ["conforming", "projection"])
@pytest.mark.parametrize("degree", [1, 2])
def test_partners_on_other_ranks(degree, pairing):
    """Every partner facet owned by another rank (split partition) gives the serial figures,
    with conforming pairs and with projected (non-matching) pairs; the projected pairs give
    the conforming figures on this conforming mesh (to the projection's Newton tolerance)."""
    world = _partner_figures(MPI.COMM_WORLD, True, degree, pairing)
    serial = _partner_figures(MPI.COMM_SELF, False, degree, pairing)
    np.testing.assert_allclose(world, serial, rtol=1e-10)
    if pairing == "projection":
        conforming = _partner_figures(MPI.COMM_SELF, False, degree, "conforming")
        np.testing.assert_allclose(serial, conforming, rtol=1e-10)


def test_history_commit_revert_and_dissipation():
    """commit() accumulates the dissipation and the plastic slip; revert() discards a trial."""
    comm = MPI.COMM_WORLD
    msh, tags = two_blocks(comm, n=(2, 2, 1))
    V = compat.vector_space(msh, 1)
    mu = 0.05
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=mu)
    ci = ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law)
    d = np.array([3e-3, 0.0, -1e-3])  # closed and sliding along x
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: np.outer(d * up, np.ones(x.shape[1])))
    res = ci.evaluate(u)
    assert comm.allreduce(int(res.slipping.sum())) == ci.n_points_global
    assert ci.dissipation() == 0.0  # nothing committed yet
    ci.commit()
    # uniform state: p = k w softplus(-g/w), slip beyond the elastic part kT|s| - mu p
    p = law.normal(np.array([d[2]]))[0][0]  # gap of the lower top: g = d_z (n = +z)
    sp = d[0] - mu * p / 5e3
    area = 1.0
    np.testing.assert_allclose(ci.dissipation(), mu * p * sp * area, rtol=1e-12)
    np.testing.assert_allclose(ci.point_fields().plastic_slip[:, 0], sp, rtol=1e-12)
    st = ci.summary()
    np.testing.assert_allclose([st.dissipation, st.max_plastic_slip], [mu * p * sp * area, sp],
                               rtol=1e-12)
    # same displacement again, from the new committed state: elastic, no new dissipation
    res = ci.evaluate(u)
    assert comm.allreduce(int(res.slipping.sum())) == 0
    # a trial that slides further, then revert: nothing of it stays
    interpolate_bodies(u, lambda x, up: np.outer(2 * d * up, np.ones(x.shape[1])))
    ci.evaluate(u)
    ci.revert()
    np.testing.assert_allclose(ci.dissipation(), mu * p * sp * area, rtol=1e-12)
    np.testing.assert_allclose(ci.history.law.committed.plastic_slip[:, 0], sp, rtol=1e-12)
    np.testing.assert_allclose(ci.history.law.trial.plastic_slip[:, 0], sp, rtol=1e-12)


@pytest.mark.parametrize("degree", [1, 2])
def test_dirichlet_dofs_are_skipped(degree):
    """Interface rows and columns of Dirichlet DOFs stay empty (bcs through the interface)."""
    comm = MPI.COMM_WORLD
    msh, tags = two_blocks(comm, n=(3, 2, 1))
    V = compat.vector_space(msh, degree)
    # x = 0 side of both blocks, u_x only (a symmetry condition through the interface edge)
    fdim = 2
    side = dmesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[0], 0.0))
    V0, _ = V.sub(0).collapse()
    dofs = fem.locate_dofs_topological((V.sub(0), V0), fdim, side)
    bc = fem.dirichletbc(fem.Function(V0), dofs, V.sub(0))
    ci, b, A = _coulomb_assembled(V, tags, bcs=[bc])
    # owned bc DOFs as global scalar indices
    local = np.asarray(bc.dof_indices()[0])
    local = local[local < 3 * V.dofmap.index_map.size_local]
    # (independent check of the index convention: x components of nodes on x = 0)
    assert np.all(local % 3 == 0)
    assert np.allclose(V.tabulate_dof_coordinates()[local // 3, 0], 0.0)
    r0 = b.getOwnershipRange()[0]
    fixed = local + r0
    assert comm.allreduce(fixed.size) > 0
    assert np.all(b.getArray()[local] == 0.0)
    # rows: zero; columns: A^T e_fixed = 0 via A^T applied to a vector supported on the bcs
    for i in fixed:
        cols, vals = A.getRow(int(i))
        assert np.all(vals == 0.0)
    e = b.duplicate()
    e.set(0.0)
    e.setValues(fixed.astype(PETSc.IntType), np.ones(fixed.size))
    e.assemble()
    y = b.duplicate()
    A.mult(e, y)
    assert y.norm() == 0.0
    # and the interface does couple the free DOFs of those nodes
    assert A.norm() > 0 and b.norm() > 0
