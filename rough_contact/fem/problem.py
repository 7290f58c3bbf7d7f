"""Bulk linear elasticity of one or more bodies plus a contact interface: residual and Jacobian.

Units: mm, N, MPa (stresses and Young's moduli in MPa = N/mm^2, forces in N, tractions in MPa,
displacements in mm, stiffness per area in MPa/mm).

The discrete problem solved at load factor ``lam`` is

    F(u) = K u - lam f + R_c(u) = 0,        J(u) = K + dR_c/du,

with ``K`` the (linear) bulk stiffness of all bodies, ``f`` the external load vector at
``lam = 1`` and ``R_c`` the interface residual of a
:class:`rough_contact.fem.contact.ContactInterface`.  The bulk part is linear, so ``K`` is
assembled once, into a matrix whose sparsity already has room for the interface blocks
(``docs/design.md``, "Sparsity" and "Bulk matrix reuse"); every Jacobian is a copy of ``K``
with the same pattern plus the interface values.

Dirichlet conditions are imposed on rows and columns of ``K`` (diagonal 1); their prescribed
values g enter the residual of the free rows through the lifting vector K_full[:, bc] g, and the
residual of a constrained row is ``x - g`` (one Newton step puts the iterate on g). Values that
change during a run — a :class:`PrescribedDisplacement` scaled by the load factor, or a user's
own ``DirichletBC`` whose value was changed followed by :meth:`ContactProblem.update_dirichlet`
— recompute the lifting (one vector assembly); a stale lifting would give a wrong residual
without any error.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import FunctionType
from typing import Optional, Sequence

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.condensation import CondensedInterface
from rough_contact.fingerprint import describe
from rough_contact.validation import check_scalar

__all__ = ["Material", "SurfaceLoad", "PrescribedDisplacement", "ContactProblem",
           "rigid_body_modes"]


@dataclass(frozen=True)
class Material:
    """Isotropic linear elastic material.

    Args:
        E: Young's modulus [MPa].
        nu: Poisson's ratio [-], in (-1, 0.5).
    """

    E: float
    nu: float

    def __post_init__(self):
        check_scalar("Young's modulus E", self.E, lo=0.0, unit="MPa")
        check_scalar("Poisson's ratio nu", self.nu, lo=-1.0, hi=0.5)

    @property
    def lame(self) -> tuple[float, float]:
        """Lame parameters (lambda, mu) [MPa]."""
        mu = self.E / (2.0 * (1.0 + self.nu))
        lmbda = self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))
        return lmbda, mu


@dataclass(frozen=True)
class SurfaceLoad:
    """A load on a tagged boundary surface, scaled by the load factor.

    Give exactly one of ``force`` (a total force spread uniformly over the surface's current
    area) or ``traction`` (force per area).

    Args:
        tag: facet tag of the loaded surface.
        force: total force vector (3,) at load factor 1 [N].
        traction: traction vector (3,) at load factor 1 [MPa].
        channel: name of the load channel that scales it (see ``ContactProblem(programs=)``;
            by default every channel follows the load factor).
    """

    tag: int
    force: Optional[Sequence[float]] = None
    traction: Optional[Sequence[float]] = None
    channel: str = "load"

    def __post_init__(self):
        if (self.force is None) == (self.traction is None):
            raise ValueError(
                f"SurfaceLoad(tag={self.tag}): give exactly one of force= or traction= "
                f"(got force={self.force!r}, traction={self.traction!r})"
            )
        name, unit = ("force", "N") if self.force is not None else ("traction", "MPa")
        vec = self.force if self.force is not None else self.traction
        if np.shape(vec) != (3,):
            raise ValueError(f"SurfaceLoad(tag={self.tag}).{name} = {vec!r} is invalid: it must "
                             f"be 3 numbers, got shape {np.shape(vec)}")
        for i, value in enumerate(vec):
            check_scalar(f"SurfaceLoad(tag={self.tag}).{name}[{i}]", value, unit=unit)


@dataclass(frozen=True)
class PrescribedDisplacement:
    """A displacement prescribed on a tagged boundary surface, scaled by the load factor:
    u = lam * value on the surface, for the chosen components (displacement control).

    Args:
        tag: facet tag of the surface.
        value: (3,) uniform displacement at load factor 1 [mm] (entries of components not
            prescribed are ignored), a callable ``x (3, n) -> (3, n)`` [mm] evaluated at the
            DOF coordinates (a non-uniform field, e.g. a rotation), or a displacement Function
            on the problem's space (its values on the surface are used).
        components: the prescribed components (0, 1, 2 = x, y, z); the others stay free.
        channel: name of the load channel that scales it (see ``ContactProblem(programs=)``).
    """

    tag: int
    value: object
    components: Sequence[int] = (0, 1, 2)
    channel: str = "load"

    def __post_init__(self):
        comps = tuple(self.components)
        if not comps or len(set(comps)) != len(comps) or any(c not in (0, 1, 2) for c in comps):
            raise ValueError(f"PrescribedDisplacement(tag={self.tag}).components = "
                             f"{self.components!r} is invalid: it must be distinct entries of "
                             "0, 1, 2 (x, y, z)")
        if not callable(self.value):     # (a dolfinx Function is callable too)
            if np.shape(self.value) != (3,):
                raise ValueError(f"PrescribedDisplacement(tag={self.tag}).value = "
                                 f"{self.value!r} is invalid: it must be 3 numbers [mm] or a "
                                 "callable x (3, n) -> (3, n)")
            for i in comps:
                check_scalar(f"PrescribedDisplacement(tag={self.tag}).value[{i}]",
                             self.value[i], unit="mm")


def rigid_body_modes(V: fem.FunctionSpace,
                     cell_groups: Sequence[np.ndarray] = ()) -> PETSc.NullSpace:
    """Near-nullspace of 3D elasticity for algebraic multigrid (GAMG).

    Args:
        V: vector P_k space on a 3D mesh.
        cell_groups: optional list of local cell index arrays, one per disconnected body; the
            six rigid modes are then built per body (6 x n_bodies vectors), which suits a mesh
            holding bodies that touch only through the contact interface.

    Returns:
        An orthonormalised PETSc near-nullspace.
    """
    imap, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    x = V.tabulate_dof_coordinates()
    n_local = imap.size_local + imap.num_ghosts
    groups = [np.arange(n_local, dtype=np.int32) if cells is None
              else np.unique(compat.cell_dofmap(V)[cells])
              for cells in (list(cell_groups) or [None])]

    def fill(k: int, basis: np.ndarray) -> None:
        blocks = groups[k // 6]
        x0, x1, x2 = x[blocks, 0], x[blocks, 1], x[blocks, 2]
        mode = k % 6
        if mode < 3:
            basis[bs * blocks + mode] = 1.0
        elif mode == 3:
            basis[bs * blocks + 0] = -x1
            basis[bs * blocks + 1] = x0
        elif mode == 4:
            basis[bs * blocks + 0] = x2
            basis[bs * blocks + 2] = -x0
        else:
            basis[bs * blocks + 2] = x1
            basis[bs * blocks + 1] = -x2

    # A rank may own no DOF of a body: its vectors are then zero locally, which is fine globally.
    return compat.near_nullspace(V, 6 * len(groups), fill)


class ContactProblem:
    """Linear elastic bodies in one mesh, coupled by a nonlinear contact interface.

    Args:
        V: vector Lagrange space (P1 or P2) on the mesh holding all bodies.
        materials: a single :class:`Material`, or a dict ``{cell_tag: Material}`` (then
            ``cell_tags`` is required and every tagged body gets its own E, nu).
        bcs: Dirichlet conditions (values are held fixed; the iterate always satisfies them).
        loads: surface loads scaled by the load factor.
        cell_tags: cell MeshTags (needed for per-body materials and per-body rigid modes).
        facet_tags: facet MeshTags (needed for surface loads and seating stiffness).
        interface: the contact interface; ``None`` gives a pure bulk problem.
        seating_tag: facet tag of a contact surface on which a small spring to ground of
            stiffness ``seating_stiffness`` [MPa/mm] is added to the JACOBIAN ONLY while no
            interface point is in contact (a body held only by contact has a singular first
            Jacobian at zero pressure; the residual is untouched so converged answers are not
            changed).
        seating_stiffness: see ``seating_tag`` [MPa/mm], >= 0.
        quadrature_degree: optional quadrature degree for the bulk forms.
        body_cells: local cell indices of each disconnected body (one array per body), for a
            near-nullspace built per body; empty = the six global rigid-body modes.
        prescribed: displacements prescribed on tagged surfaces, scaled by the load factor
            (:class:`PrescribedDisplacement`; ``facet_tags`` required).
        programs: ``{channel: scale(t)}``: the scale of each load channel as a function of the
            load factor (pseudo-time) t; a channel without a program follows t itself (today's
            proportional loading). See ``rough_contact.solver.program`` for preload, hold and
            cyclic programs.
        forms: ``(a, L)``, the user's own UFL forms instead of ``materials`` and ``loads``: the
            bilinear form a(u, v) of the bulk (linear in u; trial and test functions of V) and
            the linear form L(v) of the external loads, which forms the load channel
            ``"load"`` (scaled by the load factor or its program); ``materials`` must be None.

    Raises:
        TypeError: ``interface`` is neither a ContactInterface nor None.
        ValueError: bad materials, loads or seating stiffness (naming the quantity).
    """

    def __init__(
        self,
        V: fem.FunctionSpace,
        materials,
        bcs: Sequence[compat.DirichletBC] = (),
        loads: Sequence[SurfaceLoad] = (),
        cell_tags=None,
        facet_tags=None,
        interface: Optional[ContactInterface] = None,
        seating_tag: Optional[int] = None,
        seating_stiffness: float = 0.0,
        quadrature_degree: Optional[int] = None,
        body_cells: Sequence[np.ndarray] = (),
        prescribed: Sequence[PrescribedDisplacement] = (),
        programs: Optional[dict] = None,
        forms: Optional[tuple] = None,
    ):
        if interface is not None and not isinstance(interface, ContactInterface):
            raise TypeError(f"interface must be a ContactInterface or None, got "
                            f"{type(interface).__name__}")
        msh = V.mesh
        self.V, self.mesh, self.comm = V, msh, msh.comm
        self.bcs = list(bcs)
        self.loads = list(loads)
        self.prescribed = list(prescribed)
        self.interface = interface
        self.body_cells = [np.asarray(c, dtype=np.int32) for c in body_cells]
        self.load_factor = 0.0
        self.programs = dict(programs or {})
        for name, fn in self.programs.items():
            if not callable(fn):
                raise TypeError(f"programs[{name!r}] must be a callable t -> scale, got "
                                f"{type(fn).__name__}")
        if forms is not None:
            if materials is not None or loads:
                raise ValueError("give either forms=(a, L) or materials and loads, not both")
            self._user_forms = tuple(forms)
            if len(self._user_forms) != 2:
                raise ValueError(f"forms must be (a, L), got {len(self._user_forms)} item(s)")
        else:
            self._user_forms = None
        used = {x.channel for x in list(loads) + list(prescribed)}
        if forms is not None:
            used.add("load")
        unknown = sorted(set(self.programs) - used)
        if unknown:
            raise ValueError(f"programs given for channel(s) {unknown} that no load or prescribed "
                             f"displacement uses; channels in use: {sorted(used)}")
        self.scales = {c: 0.0 for c in used}
        self.u = fem.Function(V, name="displacement")
        self._prescribed = self._prescribed_bcs(list(prescribed), facet_tags)
        self.bcs += [bc for _, bc, *_ in self._prescribed]
        self._reaction_form = None
        self.prescribed_tags = sorted({p.tag for p in prescribed})
        if self._prescribed and interface is not None:
            interface.set_dirichlet_dofs(bcs=self.bcs)

        self._bulk_form(materials, cell_tags, facet_tags, quadrature_degree)
        self._load_vectors(facet_tags)
        self._matrices()
        self._seating(seating_tag, seating_stiffness)
        # Initial iterate satisfies the Dirichlet values.
        compat.set_bc_array(self.u.x.array, self.bcs)
        self.u.x.scatter_forward()
        self.b = self.f.duplicate()
        self.counters = {"residual": 0, "jacobian": 0, "rebuild": 0}
        self._node_keys = False              # owned_node_keys, not computed yet
        self.callback_error: Optional[BaseException] = None   # see F
        self.timings = {"bulk": 0.0, "interface_residual": 0.0, "interface_jacobian": 0.0}

    # ------------------------------------------------------------------ set-up steps
    def _bulk_form(self, materials, cell_tags, facet_tags, quadrature_degree) -> None:
        """The bilinear form of linear elasticity, per body (or the user's); the measures."""
        msh, V = self.mesh, self.V
        self._ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
        if self._user_forms is not None:
            a = self._user_forms[0]
            v, u = a.arguments()
            self.materials = {}
            self._u_trial = u
            self.a = fem.form(a)
            self._a_ufl, self._v = a, v
            return
        if isinstance(materials, Material):
            materials = {None: materials}
        elif not materials:
            raise ValueError("materials must be a Material or a non-empty {cell_tag: Material}")
        if any(tag is not None for tag in materials) and cell_tags is None:
            raise ValueError("per-body materials given by cell tag need cell_tags")
        self.materials = dict(materials)
        md = {} if quadrature_degree is None else {"quadrature_degree": quadrature_degree}
        dx = ufl.Measure("dx", domain=msh, subdomain_data=cell_tags, metadata=md)
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

        def eps(w):
            return ufl.sym(ufl.grad(w))

        self._u_trial = u
        a = 0
        for tag, mat in self.materials.items():
            lmbda, mu = mat.lame
            lmbda, mu = fem.Constant(msh, lmbda), fem.Constant(msh, mu)
            sigma = 2.0 * mu * eps(u) + lmbda * ufl.tr(eps(u)) * ufl.Identity(3)
            a += ufl.inner(sigma, eps(v)) * (dx if tag is None else dx(tag))
        self.a = fem.form(a)
        self._a_ufl, self._v = a, v

    def _load_vectors(self, facet_tags) -> None:
        """External load vectors at scale 1, one per channel (tractions from total forces use
        the surface area)."""
        msh, v, ds = self.mesh, self._v, self._ds
        self.applied_force = np.zeros(3)          # all channels at scale 1
        self._channel_force = {}
        L, L_channel = 0, {}
        if self._user_forms is not None:          # the user's load form: channel "load"
            L = L_channel["load"] = self._user_forms[1]
            full = fem_petsc.assemble_vector(fem.form(L))
            full.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            nodal = full.getArray(readonly=True).reshape(-1, 3)
            self.applied_force = self.comm.allreduce(nodal.sum(axis=0), op=MPI.SUM)
            self._channel_force["load"] = self.applied_force.copy()
            full.destroy()
        for load in self.loads:
            if facet_tags is None:
                raise ValueError("surface loads need facet_tags")
            area = self.comm.allreduce(
                fem.assemble_scalar(fem.form(fem.Constant(msh, 1.0) * ds(load.tag))), op=MPI.SUM
            )
            if area <= 0.0:
                raise ValueError(f"surface load tag {load.tag}: tagged area = {area} mm^2 is "
                                 "invalid: it must be > 0")
            if load.force is not None:
                t = np.asarray(load.force, dtype=float) / area
            else:
                t = np.asarray(load.traction, dtype=float)
            self.applied_force += t * area
            self._channel_force[load.channel] = (self._channel_force.get(load.channel, 0.0)
                                                 + t * area)
            term = ufl.inner(fem.Constant(msh, t), v) * ds(load.tag)
            L += term
            L_channel[load.channel] = L_channel.get(load.channel, 0) + term
        if L == 0:
            L = ufl.inner(fem.Constant(msh, np.zeros(3)), v) * ufl.dx(domain=msh)
        self.L = fem.form(L)
        self._L_channel = L_channel

    def _matrices(self) -> None:
        """Bulk stiffness, once, into a matrix with room for the interface blocks; the load
        vectors with and without the constrained rows; the lifting."""
        interface = self.interface
        t0 = MPI.Wtime()
        self._K_bulk = None       # the bulk matrix in its own pattern, for rebuilds (kept lazily)
        if interface is not None:
            self.K = interface.create_matrix(self.a)
        else:
            self.K = fem_petsc.create_matrix(self.a)
        self.K.zeroEntries()
        fem_petsc.assemble_matrix(self.K, self.a, bcs=self.bcs)
        self.K.assemble()
        self._condensed = isinstance(interface, CondensedInterface) and interface.condenses()
        if self._condensed:      # the tractions condensed: rows of K combined per iteration
            self.A = interface.condensed_matrix(self.K)
            self.A.setBlockSize(3)
        else:
            self.A = self.K.duplicate(copy=False)
        self.setup_time = MPI.Wtime() - t0  # [s] pattern + bulk stiffness assembly

        self.f = fem_petsc.assemble_vector(self.L)
        self.f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        # per channel, with the constrained rows (for reactions) and without (for the residual)
        self._f_channel = {}
        for name, form in self._L_channel.items():
            full = fem_petsc.assemble_vector(fem.form(form))
            full.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            free = full.copy()
            compat.set_bc(free, self.bcs, scale=0.0)
            self._f_channel[name] = (free, full)
        compat.set_bc(self.f, self.bcs, scale=0.0)
        self.lift = self.f.duplicate()
        self.update_dirichlet()
        self.f_norm = self.f.norm()

    def _seating(self, seating_tag, seating_stiffness) -> None:
        """The Jacobian-only spring on the seating surface (see the class)."""
        self.seating_stiffness = check_scalar("seating_stiffness", seating_stiffness, lo=0.0,
                                              lo_open=False, unit="MPa/mm")
        self.M_seat = None
        self._seat_form = None
        if seating_tag is not None and self.seating_stiffness > 0.0:
            k_seat = fem.Constant(self.mesh, self.seating_stiffness)
            m = fem.form(k_seat * ufl.inner(self._u_trial, self._v) * self._ds(seating_tag))
            # On the pattern of K (a superset), so it can be added with SAME_NONZERO_PATTERN.
            self._seat_form = m
            self._assemble_seating()
        self.seating_active = False

    # ------------------------------------------------------------------ PETSc callbacks
    def update_solution(self, x: PETSc.Vec) -> None:
        """Copy the SNES iterate ``x`` into ``self.u`` (with ghost values)."""
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(compat.petsc_vector(self.u))
        self.u.x.scatter_forward()

    def solution_vector(self) -> PETSc.Vec:
        """The PETSc vector of the displacement ``u`` (owned values; after changing it call
        :meth:`scatter_solution`)."""
        return compat.petsc_vector(self.u)

    def scatter_solution(self) -> None:
        """Update the ghost values of ``u`` after its owned values changed."""
        self.u.x.scatter_forward()

    def owned_solution_values(self) -> np.ndarray:
        """This rank's owned displacement values (a view) [mm]."""
        imap = self.V.dofmap.index_map
        return self.u.x.array[: imap.size_local * self.V.dofmap.index_map_bs]

    def local_solution_values(self) -> np.ndarray:
        """This rank's displacement values, owned and ghost (a view) [mm]."""
        return compat.function_values(self.u)

    def owned_node_keys(self) -> Optional[np.ndarray]:
        """(n_owned_nodes,) int64 keys of this rank's owned displacement nodes that do not
        depend on the partition (built from the indices of the geometry nodes in the arrays
        the mesh was built from: a node's own, or for P2 on simplices an edge node's two end
        vertices'), or None where the space has no such keys (``compat.node_keys``: Q2,
        degree 3, a curved geometry)."""
        if self._node_keys is False:       # computed once: the mesh does not change
            keys = compat.node_keys(self.V)
            self._node_keys = None if keys is None else keys[: self.V.dofmap.index_map.size_local]
        return self._node_keys

    def owned_dof_coordinates(self) -> np.ndarray:
        """(n_owned_nodes, 3) coordinates of this rank's owned displacement nodes [mm]."""
        return self.V.tabulate_dof_coordinates()[: self.V.dofmap.index_map.size_local]

    def begin_increment(self) -> None:
        """Start a load increment (collective): the interface's sliding pairing may re-pair on
        the committed configuration; the matrices follow its new pattern."""
        if self.interface is not None and self.interface.begin_increment(self.u):
            self.rebuild_matrices()

    def F(self, snes, x: PETSc.Vec, b: PETSc.Vec) -> None:
        """Residual ``b = K x - lam f + lift + R_c(x)``, with ``b = x - g`` on Dirichlet rows.

        An exception is kept in :attr:`callback_error` before it propagates: petsc4py 3.22
        turns an exception in an SNES callback into a ``PETSc.Error`` (3.18 passes it on as
        it is), and ``SNESSolver.solve`` re-raises the original."""
        try:
            self._residual(x, b)
        except Exception as exc:
            self.callback_error = exc
            raise

    def _residual(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        self.update_solution(x)
        t0 = MPI.Wtime()
        self.K.mult(x, b)
        for name, (free, _) in self._f_channel.items():
            b.axpy(-self.scales[name], free)
        b.axpy(1.0, self.lift)
        t1 = MPI.Wtime()
        if self.interface is not None and not self._condensed:
            self.interface.evaluate(self.u)
            self.interface.assemble_residual(b)
        if self._condensed:
            b.assemblyBegin()
            b.assemblyEnd()
            compat.set_bc(b, self.bcs, x, -1.0)
            self.interface.condense_residual(self.u, b)
        else:
            compat.set_bc(b, self.bcs, x, -1.0)
        t2 = MPI.Wtime()
        self.timings["bulk"] += t1 - t0
        self.timings["interface_residual"] += t2 - t1
        self.counters["residual"] += 1

    def _assemble_seating(self) -> None:
        self.M_seat = self.K.duplicate(copy=False)
        self.M_seat.zeroEntries()
        fem_petsc.assemble_matrix(self.M_seat, self._seat_form, bcs=self.bcs, diagonal=0.0)
        self.M_seat.assemble()

    def rebuild_matrices(self) -> None:
        """New bulk matrix K and Jacobian A (and seating matrix) with the interface's current
        pattern: after a re-pairing (moderate or large sliding) that needs blocks the old
        pattern lacks. The near-nullspace carries over; the solver notices the new ``A``
        (collective).

        The bulk values are not assembled again: at the first rebuild the bulk matrix is
        assembled once more into a matrix of its own pattern (dolfinx's, a subset of every
        interface pattern) and kept; every rebuild copies it into the new pattern (MatAXPY
        with a subset pattern: the same values, about 4 x cheaper than assembling; the kept
        matrix costs one more bulk matrix of memory, in scenes that re-pair only)."""
        ns = self.A.getNearNullSpace()
        if self._K_bulk is None:
            self._K_bulk = fem_petsc.create_matrix(self.a)
            self._K_bulk.zeroEntries()
            fem_petsc.assemble_matrix(self._K_bulk, self.a, bcs=self.bcs)
            self._K_bulk.assemble()
        self.K = self.interface.create_matrix(self.a)
        self.K.axpy(1.0, self._K_bulk, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        self.counters["rebuild"] += 1
        self.A = self.K.duplicate(copy=False)
        if self._seat_form is not None:
            self._assemble_seating()
        if ns.handle:
            self.K.setNearNullSpace(ns)
            self.A.setNearNullSpace(ns)

    def J(self, snes, x: PETSc.Vec, A: PETSc.Mat, P: PETSc.Mat) -> None:
        """Consistent Jacobian ``K + dR_c/du`` (plus the seating spring while nothing touches).

        The interface part is that of the last residual evaluation: SNES always evaluates the
        residual at an iterate before its Jacobian (its line searches end with the residual
        at the accepted iterate), so the law runs once per Newton iteration. Exceptions: see
        :meth:`F`."""
        try:
            self._jacobian(x, A, P)
        except Exception as exc:
            self.callback_error = exc
            raise

    def _jacobian(self, x: PETSc.Vec, A: PETSc.Mat, P: PETSc.Mat) -> None:
        self.update_solution(x)
        t0 = MPI.Wtime()
        if self._condensed:              # at the iterate of the last residual (SNES order)
            t1 = MPI.Wtime()
            self.interface.condense_jacobian(self.K, A)
        else:
            self.K.copy(A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            t1 = MPI.Wtime()
            if self.interface is not None:   # at the iterate of the last residual (SNES order)
                self.interface.assemble_jacobian(A)
        A.assemble()
        t2 = MPI.Wtime()
        self.seating_active = False
        if self.M_seat is not None and self.n_in_contact() == 0:
            A.axpy(1.0, self.M_seat, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN
                   if not self._condensed else PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            self.seating_active = True
        self.timings["bulk"] += t1 - t0
        self.timings["interface_jacobian"] += t2 - t1
        self.counters["jacobian"] += 1
        if P is not A:
            P.assemble()

    # ------------------------------------------------------------------ helpers
    @property
    def condensed(self) -> bool:
        """Whether the interface's enforcement condenses the contact tractions into the
        system (``rough_contact.fem.condensation.CondensedInterface``; the semismooth Newton):
        the Jacobian is then unsymmetric with constraint rows (``SNESSolver`` uses a direct
        solver)."""
        return self._condensed

    def n_in_contact(self) -> int:
        """Global number of interface points in contact at the last evaluation (collective)."""
        return 0 if self.interface is None else self.interface.n_contact()

    def set_load_factor(self, lam: float) -> None:
        """Set the load factor ``lam``: external loads and prescribed displacements are ``lam``
        times their nominal value (the lifting is recomputed when displacements are
        prescribed)."""
        self.load_factor = check_scalar("load factor", lam)
        if self.interface is not None:      # a rigid counter-surface may move with it
            self.interface.set_load_factor(self.load_factor)
        for name in self.scales:
            fn = self.programs.get(name)
            self.scales[name] = self.load_factor if fn is None else check_scalar(
                f"scale of load channel {name!r} at t = {self.load_factor:g}", fn(self.load_factor))
        if self._prescribed:
            for g, _, g1, _, _, channel in self._prescribed:
                g.x.array[:] = self.scales[channel] * g1
            self.update_dirichlet()

    def current_applied_force(self) -> np.ndarray:
        """(3,) total external surface force at the current load factor [N] (every channel at
        its current scale)."""
        f = np.zeros(3)
        for name, force in self._channel_force.items():
            f += self.scales[name] * force
        return f

    def update_dirichlet(self) -> None:
        """Recompute the lifting K_full[:, bc] g from the current Dirichlet values (collective).

        Call it after changing the value of any DirichletBC of the problem by hand;
        :meth:`set_load_factor` calls it for :class:`PrescribedDisplacement` channels.
        """
        with self.lift.localForm() as loc:
            loc.set(0.0)
        compat.apply_lifting(self.lift, [self.a], [self.bcs], scale=-1.0)
        self.lift.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        compat.set_bc(self.lift, self.bcs, scale=0.0)

    def _prescribed_bcs(self, prescribed, facet_tags):
        """(g, bc, g at lam = 1, tag, component) per prescribed component; g lives on the
        collapsed sub-space."""
        out = []
        if prescribed and facet_tags is None:
            raise ValueError("prescribed displacements need facet_tags")
        fdim = self.mesh.topology.dim - 1
        for p in prescribed:
            if not isinstance(p, PrescribedDisplacement):
                raise TypeError(f"prescribed entries must be PrescribedDisplacement, got "
                                f"{type(p).__name__}")
            facets = facet_tags.find(p.tag)
            n = self.comm.allreduce(int(facets.size), op=MPI.SUM)
            if n == 0:
                raise ValueError(f"PrescribedDisplacement(tag={p.tag}): no facet carries tag "
                                 f"{p.tag}; tags present: "
                                 f"{sorted({int(v) for v in np.concatenate(self.comm.allgather(np.unique(facet_tags.values)))})}")
            for c in p.components:
                Vc, _ = self.V.sub(c).collapse()
                dofs = fem.locate_dofs_topological((self.V.sub(c), Vc), fdim, facets)
                g1 = fem.Function(Vc)
                if isinstance(p.value, fem.Function):
                    g1.interpolate(p.value.sub(c))
                elif callable(p.value):
                    g1.interpolate(lambda x, c=c, f=p.value: np.asarray(f(x), dtype=float)[c])
                    if not np.all(np.isfinite(g1.x.array)):
                        raise ValueError(f"PrescribedDisplacement(tag={p.tag}).value returned "
                                         "non-finite displacements")
                else:
                    g1.x.array[:] = float(p.value[c])
                g = fem.Function(Vc)
                g.x.array[:] = 0.0
                out.append((g, fem.dirichletbc(g, dofs, self.V.sub(c)), g1.x.array.copy(), p.tag,
                            c, p.channel))
        return out

    def reaction(self, tag: int) -> np.ndarray:
        """(3,) force [N] the constraints of the prescribed surface ``tag`` exert on the body:
        the sum over its constrained DOFs of K_full u - lam f, per component (collective; a
        component that is not prescribed there gives 0). In equilibrium it balances the other
        forces on the body (applied loads, contact).

        Raises:
            ValueError: ``tag`` carries no PrescribedDisplacement.
        """
        if tag not in self.prescribed_tags:
            raise ValueError(f"reaction: tag {tag} carries no PrescribedDisplacement; "
                             f"prescribed tags: {self.prescribed_tags}")
        if self._reaction_form is None:
            self._reaction_form = fem.form(ufl.action(self._a_ufl, self.u))
        r = fem_petsc.assemble_vector(self._reaction_form)
        r.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        for name, (_, full) in self._f_channel.items():
            r.axpy(-self.scales[name], full)
        arr = r.getArray()
        total = np.zeros(3)
        for _, bc, _, t, c, _ in self._prescribed:
            if t == tag:
                dofs, n_owned = bc.dof_indices()
                total[c] += float(arr[np.asarray(dofs)[:n_owned]].sum())
        r.destroy()
        return self.comm.allreduce(total, op=MPI.SUM)

    def describe(self, factors: Sequence[float]) -> dict:
        """What defines this problem beyond its mesh, as canonical plain data
        (``rough_contact.fingerprint``), equal on every rank and for every rank count: the
        interface (law, pairing, quadrature, enforcement), the load program (the scale of every
        load channel at each of ``factors``), the loads and prescribed displacements, and the
        materials. A user's own forms (``forms=``) are not described."""
        program = {}
        for name in sorted(self.scales):
            fn = self.programs.get(name)
            program[name] = {f"t={float(t)!r}": repr(float(t if fn is None else fn(float(t))))
                             for t in factors}
        loads = [describe(x, "load") for x in self.loads]
        prescribed = [dict(tag=int(p.tag), components=describe(p.components),
                           channel=p.channel,
                           value=describe(p.value, "prescribed value")
                           if not callable(p.value) or isinstance(p.value, FunctionType)
                           else f"{type(p.value).__qualname__} (values not recorded)")
                      for p in self.prescribed]
        return dict(
            interface=None if self.interface is None else self.interface.describe(),
            program=program, loads=dict(surface=loads, prescribed=prescribed),
            materials=None if self._user_forms is not None else
            {str(k): describe(m, "material") for k, m in sorted(self.materials.items(),
                                                                key=lambda kv: str(kv[0]))})

    def reset_timings(self) -> None:
        for k in self.timings:
            self.timings[k] = 0.0
        for k in self.counters:
            self.counters[k] = 0

    @property
    def num_dofs(self) -> int:
        """Global number of displacement DOFs."""
        imap = self.V.dofmap.index_map
        return imap.size_global * self.V.dofmap.index_map_bs
