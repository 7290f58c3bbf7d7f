"""Contact interface operator: facet pairing, facet quadrature, jump kinematics, assembly.

DOLFINx 0.5.2 has no external operators and cannot evaluate quadrature coefficients on facets,
so the interface terms are assembled by hand; ``docs/design.md`` describes the design and the
stack facts it relies on:

* set-up (once): for every owned facet of the FIRST contact surface, its facet quadrature
  points mapped into the reference cell, the area weights and normals from the geometry map,
  the basis values of the facet-closure DOFs and their GLOBAL indices. The partner facet on
  the SECOND surface is found in a small all-gathered copy of that surface (vertex
  coordinates, KD-tree); the partner's reference coordinates reuse the barycentric
  coordinates of the point on the shared facet, which is exact for P1 and P2 geometry.
  The jump operator is stored per point: jump = B u_pair + jump0, B of shape
  (n_pts, 3, n_pair_dofs), in local axes (n, x, y).
* every evaluation: one PETSc VecScatter fetches the displacement DOFs the owned facets touch
  (wherever they are owned), the jump at all points is one batched matmul, the law is called ONCE,
  and the element vectors B^T t w and matrices B^T D B w are added with global indices.

The law is any :class:`~rough_contact.interface.contract.InterfaceLawProtocol`; its history
lives in one :class:`~rough_contact.interface.state.StatePair` (``ContactInterface.history``),
committed once per converged increment and reverted on a cutback.

Conventions (``rough_contact.interface.contract``): n is the unit normal of the first surface
pointing towards the second body, x is the grain direction projected on the facet, y = n x x.
jump = [g, s_x, s_y] are the local components of u_second - u_first (g > 0 opens). The law
returns t = dpsi/djump; the residual contribution is R = int B^T t dA and the tangent
int B^T (dt/djump) B dA. The force the interface exerts on the first body is int R_loc^T t dA.

Failures: a non-finite jump (checked before the law is called), a non-finite traction or
tangent and a law's own :class:`~rough_contact.interface.contract.ConvergenceError` raise
``ConvergenceError`` on every rank (the load stepping cuts back); any other exception of the
law propagates with its type on the failing rank and as a ``RuntimeError`` naming it on the
others (:func:`rough_contact.fem.collective.raise_on_all_ranks`).

Rigid obstacle (``second_tag=None``): u_second = 0. With ``rigid_plane=(point, normal)``
(``normal`` = unit normal of the plane pointing towards the first body) the local normal is
-normal everywhere and the initial gap is the distance of each point from the plane;
without a plane, the plane is taken tangent to the first surface at every point (n = facet
normal, zero initial gap).

Units: mm, N, MPa. Positions and jumps [mm], tractions [MPa], forces [N], areas [mm^2].
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from typing import Optional, Sequence, Tuple, Union

import basix
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc
from scipy.spatial import cKDTree

import dolfinx
import dolfinx.cpp
import dolfinx.fem
from rough_contact.fem.collective import raise_on_all_ranks
from rough_contact.fem.pairing import (SecondSurface, _newton_on_facets, cyclic_order,
                                       mortar_points, project_points, tabulate)
from rough_contact.fem.rigid import RigidPlane as RigidPlaneSurface
from rough_contact.fem.rigid import RigidSurface
from rough_contact.interface.contract import (
    AugmentationControl,
    AugmentedLagrangianLaw,
    ConvergenceError,
    InterfaceLawProtocol,
    LawContractError,
    LawResult,
    LawState,
    NewtonTangentLaw,
)
from rough_contact.interface.state import StatePair
from rough_contact.validation import check_scalar

__all__ = ["ContactInterface", "InterfaceSummary", "PointFields"]

RigidPlane = Tuple[Sequence[float], Sequence[float]]  # (point (3,), unit normal (3,)) [mm]


@dataclass(frozen=True)
class InterfaceSummary:
    """Global (all-rank) figures of the interface, identical on every rank.

    Contact, slip, force and areas are those of the last evaluation; the dissipation is the
    committed one (summed over converged increments).

    Attributes:
        n_points: number of interface quadrature points (without the weight-0 copies that
            fill the slots of the mortar pairing).
        n_contact: points with p > 0.
        n_slipping: points where the friction limit is active.
        contact_force: (3,) force on the FIRST body's surface in global axes [N].
        real_area: real contact area int A/A0 dA [mm^2].
        nominal_area: area of the first contact surface [mm^2].
        contact_area: nominal area of the points in contact [mm^2].
        slipping_area: nominal area of the slipping points [mm^2].
        max_slip: largest |(s_x, s_y)| [mm].
        max_plastic_slip: largest |plastic slip| of the trial state [mm].
        dissipation: committed accumulated frictional dissipation int D dA [N mm].
        n_beyond_validity: points where the law reports evaluation outside its model's range
            (``LawResult.beyond_validity``; 0 for a law without such a limit).
    """

    n_points: int
    n_contact: int
    n_slipping: int
    contact_force: np.ndarray
    real_area: float
    nominal_area: float
    contact_area: float
    slipping_area: float
    max_slip: float
    max_plastic_slip: float
    dissipation: float
    n_beyond_validity: int = 0


@dataclass(frozen=True)
class PointFields:
    """Local (this rank's) fields at the interface quadrature points, for output.

    Attributes:
        pressure: (n,) p = -t_N [MPa].
        shear: (n, 2) (t_x, t_y) [MPa].
        area_fraction: (n,) A/A0 [-].
        gap: (n,) normal jump g [mm].
        slip: (n, 2) tangential jump (s_x, s_y) [mm].
        plastic_slip: (n, 2) plastic slip of the trial state [mm].
        dissipation: (n,) committed accumulated dissipation per area [N/mm].
        contact: (n,) bool.
        slipping: (n,) bool.
        weight: (n,) quadrature weight = area represented by the point [mm^2].
    """

    pressure: np.ndarray
    shear: np.ndarray
    area_fraction: np.ndarray
    gap: np.ndarray
    slip: np.ndarray
    plastic_slip: np.ndarray
    dissipation: np.ndarray
    contact: np.ndarray
    slipping: np.ndarray
    weight: np.ndarray


def _owned_tagged_facets(facet_tags, tag: int, n_owned: int, comm) -> np.ndarray:
    facets = np.asarray(facet_tags.indices[facet_tags.values == tag], dtype=np.int32)
    facets = np.unique(facets[facets < n_owned])
    if comm.allreduce(facets.size, op=MPI.SUM) == 0:
        gathered = comm.allgather(np.unique(facet_tags.values))
        present = sorted({int(v) for arr in gathered for v in arr})
        raise ValueError(f"contact facet tag {tag} marks no facet; tags present: {present}")
    return facets


class _FacetGeometry:
    """Geometry and basis data of a set of exterior facets, vectorised over facets."""

    def __init__(self, V, facets: np.ndarray):
        msh = V.mesh
        tdim = msh.topology.dim
        self.facets = facets
        f_to_c = msh.topology.connectivity(tdim - 1, tdim)
        counts = f_to_c.offsets[facets + 1] - f_to_c.offsets[facets]
        if np.any(counts != 1):
            raise ValueError(
                f"{int(np.sum(counts != 1))} contact facets are interior facets (shared by two "
                "cells); a contact surface must be an exterior facet of one body"
            )
        self.cells = f_to_c.array[f_to_c.offsets[facets]]
        cell = _basix_cell(msh)
        n_lf = len(basix.topology(cell)[2])
        c_to_f = msh.topology.connectivity(tdim, tdim - 1).array.reshape(-1, n_lf)
        self.local_facet = np.argmax(c_to_f[self.cells] == facets[:, None], axis=1)

        x = msh.geometry.x
        n_gdof = _cmap_element(msh).dim
        gdofs = msh.geometry.dofmap.array.reshape(-1, n_gdof)
        self.cell_nodes_x = x[gdofs[self.cells]]  # (n_f, n_gdof, 3)
        # facet vertices in the reference facet's vertex order (geometry dofs 0..3 = vertices)
        ref_facet_vertices = np.array(basix.topology(cell)[2])
        self.vertex_x = x[gdofs[self.cells[:, None], ref_facet_vertices[self.local_facet]]]

        element = V.element.basix_element
        self.closure = np.array(element.entity_closure_dofs[2])  # (4, n_close)
        dofs = V.dofmap.list.array.reshape(-1, element.dim)
        local_nodes = np.take_along_axis(
            dofs[self.cells], self.closure[self.local_facet], axis=1
        )
        self.local_nodes = local_nodes                 # (n_f, n_close) local block indices
        self.global_nodes = V.dofmap.index_map.local_to_global(
            local_nodes.ravel().astype(np.int32)
        ).reshape(local_nodes.shape).astype(np.int64)


class ContactInterface:
    """Interface operator between two tagged surfaces (or one surface and a rigid plane).

    Args:
        V: vector Lagrange space of degree 1 or 2 (P1/P2 tetrahedra, Q1/Q2 hexahedra) on the
            mesh holding both bodies.
        facet_tags: MeshTags on facets.
        first_tag: tag of the first contact surface (its normal defines the local axes).
        second_tag: tag of the conforming second surface, or None for a rigid obstacle.
        law: the interface law (:class:`~rough_contact.interface.contract.InterfaceLawProtocol`:
            ``initial_state(n)`` and ``evaluate(jump, committed) -> LawResult``).
        rigid_plane: for ``second_tag=None``: (point (3,), unit normal (3,) pointing towards the
            first body) [mm]; None = a plane tangent to the first surface at every point.
        rigid: for ``second_tag=None``: any rigid counter-surface
            (:class:`rough_contact.fem.rigid.RigidSurface`: plane, sphere, cylinder, signed
            distance); its gap and normal are evaluated at set-up and linearised (small
            sliding, see ``rough_contact.fem.rigid``). Give ``rigid`` or ``rigid_plane``.
        grain_direction: (3,) global direction projected on the facet to give the local x axis.
        quadrature_degree: degree (integer >= 0) of the facet quadrature rule (Gauss).
        quadrature: ``"gauss"`` (default: Gauss points of ``quadrature_degree``) or
            ``"vertex"``: the facet's vertices with equal weights (nodal, "lumped" integration;
            P1/Q1 spaces only). With the vertex rule the law is evaluated once per surface node
            (the facets sharing a node see the same jump) and every node carries one
            constraint; Gauss rules put 3 (P1, degree 2) or more points per facet, i.e. about
            6 constraints per node of a triangulated surface, which a stiff penalty over-
            constrains: pressures and stick/slip then depend on the penalty and the rule
            (docs/solver.md, the Coulomb punch). ``quadrature_degree`` is ignored.
        bcs: Dirichlet conditions whose DOFs the interface must not touch (also
            ``set_dirichlet_dofs``).
        match_tolerance: vertex matching tolerance relative to the facet size [-], > 0.
        pairing: how the second surface is paired with the first one: ``"conforming"`` (facet
            to facet, the surfaces must be the same surface mesh: exact node-to-node
            kinematics), ``"projection"`` (every quadrature point projected along the first
            normal onto the second surface's facets: non-matching meshes, see
            :mod:`rough_contact.fem.pairing`) or ``"auto"`` (default: conforming if every
            facet finds its match, else projection; ``pairing_used`` tells which).
        search_radius: for projection: the largest accepted distance between a first-surface
            point and its partner along the normal [mm], > 0; default: the largest facet
            diameter of the first surface. Points without partner within it are an error.
        sliding: ``"small"`` (default: partners found once, at set-up — the paper's
            kinematics) or ``"moderate"``: the projection is redone on the deformed surfaces
            after every converged increment (:meth:`update_pairing`, called by
            ``load_path``), so a body can slide over several elements of the other. Needs a
            deformable second surface, the projection pairing (forced; not the mortar) and a
            displacement space of the geometry's degree. See :meth:`update_pairing` for the
            kinematics.

    Attributes:
        history: committed and trial law state and the accumulated dissipation
            (:class:`~rough_contact.interface.state.StatePair`).
        n_points, n_points_global: interface quadrature points on this rank / on all ranks.
        pairing_used: ``"conforming"``, ``"projection"``, ``"mortar"`` or ``"rigid"``.
        sliding: ``"small"`` or ``"moderate"``.
        n_repairs: how many times :meth:`update_pairing` changed a partner facet.
        n_groups: pairs of (first facet, partner facet) on this rank: the element blocks
            assembled (= n_facets for conforming pairs and rigid obstacles).

    Raises:
        TypeError: ``law`` does not satisfy the protocol (names the missing methods).
        LawContractError: ``law.initial_state`` returns no valid ``LawState``.
        ValueError: unknown/empty tags, unsupported spaces, surfaces that do not match.
    """

    def __init__(
        self,
        V: dolfinx.fem.FunctionSpace,
        facet_tags,
        first_tag: int,
        second_tag: Optional[int] = None,
        *,
        law: InterfaceLawProtocol,
        rigid_plane: Optional[RigidPlane] = None,
        rigid: Optional[RigidSurface] = None,
        grain_direction: Sequence[float] = (1.0, 0.0, 0.0),
        quadrature_degree: int = 2,
        quadrature: str = "gauss",
        bcs: Sequence[dolfinx.fem.DirichletBCMetaClass] = (),
        match_tolerance: float = 1e-6,
        pairing: str = "auto",
        search_radius: Optional[float] = None,
        sliding: str = "small",
    ):
        self.comm = V.mesh.comm
        self.V = V
        self.law = law
        if rigid is not None:
            if rigid_plane is not None:
                raise ValueError("give either rigid or rigid_plane, not both")
            if second_tag is not None:
                raise ValueError("give either second_tag or rigid, not both")
            if not isinstance(rigid, RigidSurface):
                raise TypeError(f"rigid ({type(rigid).__name__}) must implement "
                                "rough_contact.fem.rigid.RigidSurface (gap_and_normal(x))")
        elif rigid_plane is not None:
            _plane(rigid_plane)                         # validates with its own message
            rigid = RigidPlaneSurface(*rigid_plane)     # normalises once, as before
        grain, degree = _check_arguments(V, law, first_tag, second_tag, rigid_plane,
                                         quadrature_degree, grain_direction, match_tolerance,
                                         quadrature)
        if pairing not in ("auto", "conforming", "projection", "mortar"):
            raise ValueError(f"pairing = {pairing!r} is invalid: it must be 'auto', "
                             "'conforming', 'projection' or 'mortar'")
        if search_radius is not None:
            check_scalar("search_radius", search_radius, lo=0.0, unit="mm")
        if sliding not in ("small", "moderate"):
            raise ValueError(f"sliding = {sliding!r} is invalid: it must be 'small' or "
                             "'moderate'")
        if sliding == "moderate":
            if second_tag is None or pairing not in ("auto", "projection"):
                raise ValueError(
                    f"sliding = 'moderate' needs a deformable second surface (second_tag) and "
                    f"the projection pairing (pairing 'auto' or 'projection', got {pairing!r}, "
                    f"second_tag {second_tag!r})")
            if V.ufl_element().degree() != V.mesh.geometry.cmap.degree:
                raise ValueError(
                    f"sliding = 'moderate' needs a displacement space of the geometry's degree "
                    f"({V.mesh.geometry.cmap.degree}), got {V.ufl_element().degree()}")
            pairing = "projection"
        self.sliding = sliding
        self.n_repairs = 0
        self._dirichlet = (None, list(bcs))
        self.first_tag, self.second_tag = first_tag, second_tag
        n_owned_facets = _facet_connectivity(V.mesh)
        rule = _FacetRule.create(V.mesh, degree, vertex=quadrature == "vertex")
        if quadrature == "gauss":
            _warn_overconstrained(law, rule.nq, V.mesh.topology.cell_type,
                                  V.ufl_element().degree(), degree)
        geo1 = _FacetGeometry(V, _owned_tagged_facets(facet_tags, first_tag, n_owned_facets,
                                                      self.comm))
        self._facets1 = geo1.facets
        if pairing == "mortar":
            if second_tag is None or quadrature != "gauss":
                raise ValueError("pairing = 'mortar' needs a second surface (second_tag) and "
                                 "the Gauss rule (quadrature='gauss')")
            xq, normal, N1, mortar = self._mortar_surface(facet_tags, second_tag,
                                                          n_owned_facets, geo1, degree,
                                                          search_radius)
        else:
            xq, normal, N1 = self._first_surface(geo1, rule)
        R = self._local_axes(xq, normal, grain, rigid)
        if pairing == "mortar":
            paired = mortar
            self.pairing_used = "mortar"
        elif second_tag is None:
            paired = None
            self.n_remote_partners = 0
            self.pairing_used = "rigid"
        else:
            paired = None
            if pairing != "projection":
                paired = self._pair_second_surface(facet_tags, second_tag, n_owned_facets, geo1,
                                                   rule, match_tolerance,
                                                   strict=pairing == "conforming")
            self.pairing_used = "conforming" if paired is not None else "projection"
            if paired is None:
                paired = self._project_second_surface(facet_tags, second_tag, n_owned_facets,
                                                      geo1, xq, R, search_radius)
        if sliding == "moderate":   # what update_pairing needs
            self._N1, self._nodes1, self._local_nodes1 = N1, geo1.global_nodes, geo1.local_nodes
            self._R_full = R
            self._partner_facet = paired.facet.reshape(-1).copy()
            self._projection = None          # set-up pairing: rebuilt identically
        self._matrix_keys: set = set()
        self._jump_operator(R, N1, geo1.global_nodes, paired)
        self._communication(bcs)
        self.history = self._initial_history()
        self._last_u = self._last = self._last_jump = None
        self._newton_memo = None   # a law's newton_tangent memo within one Newton solve
        self._augment_base = None  # committed state before this increment's multiplier updates
        self._multipliers_before = None  # committed state the last converged increment began at
        self._cache_valid = False
        self._result_checked = False  # the first evaluation's result is checked in full

    # ------------------------------------------------------------------ set-up steps
    def _first_surface(self, geo1: _FacetGeometry, rule: _FacetRule):
        """Quadrature points, area weights, unit normals and basis values on the first surface.

        Returns:
            xq: (n_f, nq, 3) physical points [mm]; normal: (n_f, nq, 3) outward unit normals;
            N1: (n_f, nq, n_close) values of the facet-closure basis functions at the points.
        """
        n_f, nq = geo1.facets.size, rule.nq
        self.n_facets, self.n_qp = n_f, nq
        cmap_el = _cmap_element(self.V.mesh)
        n_lf = rule.points.shape[0]
        tab_g = cmap_el.tabulate(1, rule.points.reshape(-1, 3)).reshape(4, n_lf, nq, cmap_el.dim)
        lf1 = geo1.local_facet
        phi_g = tab_g[0][lf1]  # (n_f, nq, n_gdof)
        dphi_g = np.moveaxis(tab_g[1:], 0, -1)[lf1]  # (n_f, nq, n_gdof, 3)
        xq = np.einsum("fqk,fki->fqi", phi_g, geo1.cell_nodes_x)
        J = np.einsum("fki,fqkd->fqid", geo1.cell_nodes_x, dphi_g)  # (n_f, nq, 3, 3)
        t12 = np.einsum("fqid,fde->fqie", J, rule.tangents[lf1])  # (n_f, nq, 3, 2)
        nvec = np.cross(t12[..., 0], t12[..., 1])
        dA = np.linalg.norm(nvec, axis=-1)
        # physical outward direction J^-T N_ref fixes the sign of t1 x t2
        n_ref = np.broadcast_to(rule.normals[lf1][:, None, :, None], J.shape[:-1] + (1,))
        outward = np.linalg.solve(np.swapaxes(J, -1, -2), n_ref)[..., 0]
        sign = np.sign(np.einsum("fqi,fqi->fq", nvec, outward))
        normal = sign[..., None] * nvec / dA[..., None]
        self._weights = (rule.weights[None, :] * dA).reshape(-1)
        self._x = xq.reshape(-1, 3)
        element = self.V.element.basix_element
        phi = element.tabulate(0, rule.points.reshape(-1, 3))[0].reshape(n_lf, nq, element.dim)
        N1 = np.take_along_axis(phi[lf1], geo1.closure[lf1][:, None, :], axis=2)
        return xq, normal, N1

    def _local_axes(self, xq: np.ndarray, normal: np.ndarray, grain: np.ndarray,
                    rigid: Optional[RigidSurface]) -> np.ndarray:
        """Local frames (n, x, y) per point and the initial gap to a rigid surface (collective).

        Returns:
            R: (n_f, nq, 3 local, 3 global) rows n, x, y.
        """
        jump0 = np.zeros(xq.shape)
        if rigid is not None:
            g0, rnormal = rigid.gap_and_normal(xq.reshape(-1, 3))
            normal = -np.asarray(rnormal, dtype=float).reshape(normal.shape)
            jump0[..., 0] = np.asarray(g0, dtype=float).reshape(jump0.shape[:-1])
        gx = grain - np.einsum("fqi,i->fq", normal, grain)[..., None] * normal
        gnorm = np.linalg.norm(gx, axis=-1)
        bad = gnorm < 1e-6 * np.linalg.norm(grain)
        n_bad = self.comm.allreduce(int(bad.sum()), op=MPI.SUM)
        if n_bad:
            raise ValueError(
                f"grain_direction {grain.tolist()} is (nearly) normal to the contact surface at "
                f"{n_bad} points; choose a direction lying in the surface"
            )
        ex = gx / gnorm[..., None]
        ey = np.cross(normal, ex)
        R = np.stack([normal, ex, ey], axis=-2)  # (n_f, nq, 3 local, 3 global)
        self._R = R.reshape(-1, 3, 3)
        self._jump0 = jump0.reshape(-1, 3)
        return R

    def _pair_second_surface(self, facet_tags, second_tag: int, n_owned_facets: int,
                             geo1: _FacetGeometry, rule: _FacetRule, match_tolerance: float,
                             strict: bool = True) -> Optional[_Partners]:
        """Conforming partner facets on the second surface, from an all-gathered copy of it
        (collective).

        Returns:
            The partners, or None if some facet has no match and ``strict`` is False.

        Raises:
            ValueError: some facet has no match and ``strict`` is True.
        """
        comm = self.comm
        n_f, nq, nv = geo1.facets.size, rule.nq, rule.lam.shape[1]
        element = self.V.element.basix_element
        n_close = geo1.closure.shape[1]
        geo2 = _FacetGeometry(self.V, _owned_tagged_facets(facet_tags, second_tag,
                                                           n_owned_facets, comm))
        gathered = comm.allgather((geo2.vertex_x, geo2.local_facet, geo2.global_nodes))
        owner2 = np.concatenate(
            [np.full(g[1].size, r, dtype=np.int64) for r, g in enumerate(gathered)]
        )
        vx2 = np.concatenate([g[0] for g in gathered]).reshape(-1, nv, 3)
        lf2_all = np.concatenate([g[1] for g in gathered]).astype(np.int64)
        nodes2_all = np.concatenate([g[2] for g in gathered]).reshape(-1, n_close)
        vx1 = geo1.vertex_x  # (n_f, nv, 3)
        size = np.linalg.norm(vx1[:, 1] - vx1[:, 0], axis=1) if n_f else np.zeros(0)
        tol = match_tolerance * size
        partner = np.zeros(n_f, dtype=np.int64)
        ok = np.zeros(n_f, dtype=bool)
        perm = np.zeros((n_f, nv), dtype=np.int64)
        if n_f and vx2.shape[0]:
            tree = cKDTree(vx2.mean(axis=1))
            _, partner = tree.query(vx1.mean(axis=1), k=1)
            d = np.linalg.norm(vx1[:, :, None, :] - vx2[partner][:, None, :, :], axis=-1)
            perm = np.argmin(d, axis=2)  # first vertex i <-> partner vertex perm[i]
            ok = (np.max(np.min(d, axis=2), axis=1) <= tol) & (
                np.sort(perm, axis=1) == np.arange(nv)
            ).all(axis=1)
        n_bad = comm.allreduce(int(np.sum(~ok)), op=MPI.SUM)
        if n_bad and not strict:
            return None
        if n_bad:
            example = comm.allgather(vx1[~ok].mean(axis=1)[0].tolist() if np.any(~ok) else None)
            example = next(e for e in example if e is not None)
            n_total = comm.allreduce(n_f, op=MPI.SUM)
            raise ValueError(
                f"{n_bad} of {n_total} facets of contact surface {self.first_tag} have no "
                f"matching facet on surface {second_tag} (vertex tolerance {match_tolerance} x "
                f"facet size), e.g. the facet with centroid {example}; the interface must be "
                "conforming (same surface mesh on both sides)"
            )
        lf2 = lf2_all[partner]
        self.n_remote_partners = int(np.sum(owner2[partner] != comm.rank))
        # barycentric reuse: the point with weights lam on the first facet's vertices
        X2 = np.einsum(
            "qi,fid->fqd", rule.lam, rule.vertices[lf2][np.arange(n_f)[:, None], perm]
        )  # (n_f, nq, 3)
        phi2 = (
            element.tabulate(0, X2.reshape(-1, 3))[0].reshape(n_f, nq, element.dim)
            if n_f
            else np.zeros((0, nq, element.dim))
        )
        closure2 = geo1.closure[lf2]  # same element on both sides
        N2 = np.take_along_axis(phi2, closure2[:, None, :], axis=2)
        shape = (n_f, nq)
        return _Partners(
            N2=N2, nodes2=np.broadcast_to(nodes2_all[partner][:, None, :], shape + (n_close,)),
            facet=np.broadcast_to(partner[:, None], shape),
            remote=np.broadcast_to((owner2[partner] != comm.rank)[:, None], shape),
            gap0=np.zeros(shape))

    def _project_second_surface(self, facet_tags, second_tag: int, n_owned_facets: int,
                                geo1: _FacetGeometry, xq: np.ndarray, R: np.ndarray,
                                search_radius: Optional[float]) -> _Partners:
        """Non-matching partners: every point projected along its normal onto an all-gathered
        copy of the second surface (:func:`rough_contact.fem.pairing.project_points`;
        collective).

        Raises:
            ValueError (on every rank): points without partner within the search radius, or
                whose only candidates face the wrong way (count, first coordinates, the
                nearest distance found).
        """
        comm = self.comm
        msh = self.V.mesh
        n_f, nq = xq.shape[:2]
        second = _GatheredSurface.create(self.V, facet_tags, second_tag, n_owned_facets)
        surface = second.surface
        if search_radius is None:
            vx1 = geo1.vertex_x
            diam = (np.linalg.norm(vx1[:, :, None] - vx1[:, None], axis=-1).max(initial=0.0)
                    if n_f else 0.0)
            search_radius = comm.allreduce(float(diam), op=MPI.MAX)
        self.search_radius = search_radius
        self._second = second
        x = xq.reshape(-1, 3)
        normal = R[..., 0, :].reshape(-1, 3)
        proj = project_points(x, normal, surface, _cmap_element(msh), search_radius)
        self._check_partners(proj, x, search_radius, second_tag)
        return self._partners(proj, (n_f, nq))

    def _check_partners(self, proj, x, search_radius, second_tag, after=""):
        comm = self.comm
        missing = proj.facet < 0
        n_missing = comm.allreduce(int(missing.sum()), op=MPI.SUM)
        if n_missing:
            n_facing = comm.allreduce(int(proj.facing_failure.sum()), op=MPI.SUM)
            first = comm.allgather(x[missing][:3].tolist() if missing.any() else [])
            first = [p for r in first for p in r][:3]
            nearest = comm.allreduce(float(proj.nearest[missing].min(initial=np.inf)),
                                     op=MPI.MIN)
            n_total = comm.allreduce(x.shape[0], op=MPI.SUM)
            why = (f"{n_facing} of them only found facets of surface {second_tag} that face the "
                   "same way (the surfaces must face each other: check the tags and the "
                   "bodies they belong to); " if n_facing else "")
            found = (f"the nearest partner found along the normal of such a point is "
                     f"{nearest:.6g} mm away" if np.isfinite(nearest) else
                     "no facet of the second surface lies on their normals")
            raise ValueError(
                f"{after}{n_missing} of {n_total} quadrature points of contact surface "
                f"{self.first_tag} have no partner on surface {second_tag} within the search "
                f"radius {search_radius:.6g} mm along their normal; {why}{found}; first "
                f"points: {first}. Check that the surfaces overlap and face each other, or "
                "raise search_radius")

    def _partners(self, proj, shape) -> _Partners:
        """Partner data of a complete projection onto the gathered second surface."""
        comm = self.comm
        second = self._second
        owner2, lf2_all, nodes2_all = second.owner, second.local_facet, second.nodes
        n_close, closure = nodes2_all.shape[1], second.closure
        lf2 = lf2_all[proj.facet]
        phi2 = tabulate(self.V.element.basix_element, 0, proj.X_ref)[0]
        N2 = np.take_along_axis(phi2, closure[lf2], axis=1)
        self.n_remote_partners = int(np.sum(owner2[proj.facet] != comm.rank))
        return _Partners(N2=N2.reshape(shape + (n_close,)),
                         nodes2=nodes2_all[proj.facet].reshape(shape + (n_close,)),
                         facet=proj.facet.reshape(shape),
                         remote=(owner2[proj.facet] != comm.rank).reshape(shape),
                         gap0=proj.distance.reshape(shape))

    def _mortar_surface(self, facet_tags, second_tag: int, n_owned_facets: int,
                        geo1: _FacetGeometry, degree: int, search_radius: Optional[float]):
        """Segment-to-segment points: the first facets clipped by the second surface's facets
        projected on their planes, a triangle rule of ``degree`` on every piece
        (:func:`rough_contact.fem.pairing.mortar_points`; collective).

        Every first facet gets the same number of point slots (the largest count on any
        rank): a facet with fewer pieces repeats its first point with weight 0.

        Returns:
            xq (n_f, nq, 3), normal (n_f, nq, 3), N1 (n_f, nq, n_close), weights (n_f * nq,),
            and the partners.

        Raises:
            ValueError (on every rank): a part of the first surface is not covered by the
                second surface (uncovered area, facet count, first centroid).
        """
        comm = self.comm
        msh = self.V.mesh
        element = self.V.element.basix_element
        cmap = _cmap_element(msh)
        second = _GatheredSurface.create(self.V, facet_tags, second_tag, n_owned_facets)
        first = _facet_set(msh, geo1.cell_nodes_x, geo1.local_facet, geo1.vertex_x)
        facet_cell = _CELLS[msh.topology.cell_type][1]
        pts, wts = basix.make_quadrature(basix.CellType.triangle, degree)
        mp = mortar_points(first, geo1.vertex_x, second.surface, second.vertex_x, pts, wts)
        n_f = geo1.facets.size
        # coverage: every first facet's area must be matched by overlaps
        vx = geo1.vertex_x[:, cyclic_order(geo1.vertex_x.shape[1])]
        plane_n = np.cross(vx[:, 1] - vx[:, 0], vx[:, -1] - vx[:, 0]) if n_f else np.zeros((0, 3))
        area = np.linalg.norm(plane_n, axis=1) * (0.5 if facet_cell == basix.CellType.triangle
                                                  else 1.0)
        covered = np.bincount(mp.facet1, weights=mp.weight, minlength=n_f)
        gap_area = np.clip(area - covered, 0.0, None)
        bad = gap_area > 1e-8 * area
        n_bad = comm.allreduce(int(bad.sum()), op=MPI.SUM)
        if n_bad:
            lost = comm.allreduce(float(gap_area[bad].sum()), op=MPI.SUM)
            total = comm.allreduce(float(area.sum()), op=MPI.SUM)
            first_c = comm.allgather(vx[bad].mean(axis=1)[0].tolist() if bad.any() else None)
            first_c = next(c for c in first_c if c is not None)
            raise ValueError(
                f"{n_bad} facets of contact surface {self.first_tag} are not fully covered by "
                f"surface {second_tag}: {lost:.6g} of {total:.6g} mm^2 have no partner "
                f"(first such facet centred at {first_c}); with pairing='mortar' the first "
                "surface must lie within the second one (make the smaller surface the first)")
        # points on the first facets: reference coordinates, normals, basis values
        plane_n = plane_n / np.maximum(np.linalg.norm(plane_n, axis=1), 1e-300)[:, None]
        X1, _, conv1, _, _ = _newton_on_facets(mp.x, plane_n[mp.facet1], first, mp.facet1, cmap)
        order = np.argsort(mp.facet1, kind="stable")
        counts = np.bincount(mp.facet1, minlength=n_f)
        nq = comm.allreduce(int(counts.max(initial=1)), op=MPI.MAX)
        starts = np.cumsum(counts) - counts
        slot = np.arange(nq)[None, :]
        take = order[np.minimum(starts[:, None] + slot, starts[:, None] + counts[:, None] - 1)]
        real = slot < counts[:, None]                       # (n_f, nq)
        take = take.reshape(-1) if n_f else np.zeros(0, dtype=np.int64)
        X1 = X1[take]
        weights = np.where(real.reshape(-1), mp.weight[take], 0.0)
        lf1 = np.repeat(geo1.local_facet, nq)
        cell_x = np.repeat(geo1.cell_nodes_x, nq, axis=0)
        tab = tabulate(cmap, 1, X1)
        xq = np.einsum("pk,pki->pi", tab[0], cell_x)
        J = np.einsum("pki,pkd->pid", cell_x, np.moveaxis(tab[1:], 0, -1))
        ref_normals = basix.cell.facet_outward_normals(_basix_cell(msh))
        outward = np.linalg.solve(np.swapaxes(J, 1, 2), ref_normals[lf1][:, :, None])[..., 0] \
            if X1.shape[0] else np.zeros((0, 3))
        normal = outward / np.maximum(np.linalg.norm(outward, axis=1), 1e-300)[:, None]
        phi = tabulate(element, 0, X1)[0]
        N1 = np.take_along_axis(phi, geo1.closure[lf1], axis=1)
        # partner points on the second facets, along the first normal
        f2 = mp.facet2[take]
        X2, gap0, conv2, _, facing = _newton_on_facets(xq, normal, second.surface, f2, cmap)
        if search_radius is None:
            search_radius = comm.allreduce(float(np.sqrt(area.max(initial=0.0))), op=MPI.MAX)
        failed = ~(conv1[take] & conv2 & facing)
        far = ~failed & (np.abs(gap0) > search_radius)
        n_failed, n_far = comm.allreduce(np.array([failed.sum(), far.sum()]), op=MPI.SUM)
        if n_failed or n_far:
            dist = comm.allreduce(float(np.abs(gap0[far]).max(initial=0.0)), op=MPI.MAX)
            raise ValueError(
                f"{n_failed + n_far} mortar points of contact surface {self.first_tag} have no "
                f"partner on surface {second_tag}: {n_failed} whose partner facet faces the "
                f"same way or cannot be reached along their normal, {n_far} farther than the "
                f"search radius {search_radius:.6g} mm (up to {dist:.6g} mm); the surfaces "
                "must face each other and touch (check the tags and the bodies they belong "
                "to)")
        phi2 = tabulate(element, 0, X2)[0]
        N2 = np.take_along_axis(phi2, second.closure[second.local_facet[f2]], axis=1)
        shape = (n_f, nq)
        self.n_facets, self.n_qp = n_f, nq
        self._weights = weights
        self._x = xq
        n_close = N1.shape[1]
        partners = _Partners(N2=N2.reshape(shape + (n_close,)),
                             nodes2=second.nodes[f2].reshape(shape + (n_close,)),
                             facet=f2.reshape(shape),
                             remote=(second.owner[f2] != comm.rank).reshape(shape),
                             gap0=gap0.reshape(shape),
                             copy_of=np.where(real, -1, np.arange(n_f)[:, None] * nq))
        return (xq.reshape(shape + (3,)), normal.reshape(shape + (3,)),
                N1.reshape(shape + (n_close,)), partners)

    def _jump_operator(self, R: np.ndarray, N1: np.ndarray, nodes1: np.ndarray,
                       partners: Optional[_Partners]) -> None:
        """B per point: jump = B u_pair + jump0 in local axes.

        Points are grouped into element blocks ("groups"): one per (first facet, partner facet)
        pair, holding the first facet's points whose partner lies on that facet (all the
        facet's points for conforming pairs and rigid obstacles, so a group is a facet). A
        group's columns are the closure DOFs of both facets in ascending global order (PETSc
        inserts sorted columns faster); it has ``nqs`` point slots, unused ones (fewer points
        than slots) have B = 0 and take no weight. ``_point_slot`` maps each point to its slot;
        a slot-filling copy (``partners.copy_of``, weight 0) shares the slot of the point it
        repeats, so it costs nothing in the assembly.
        """
        n_f, nq, n_close = N1.shape
        B1 = -np.einsum("fqac,fqk->fqakc", R, N1).reshape(n_f, nq, 3, 3 * n_close)
        if partners is None:
            groups_of_facet = np.arange(n_f)
            group_facet = np.arange(n_f)
            slot = np.tile(np.arange(nq), n_f)
            nqs, n_g = nq, n_f
            B = B1
            nodes = nodes1
        else:
            if partners.facet.size:
                key = np.arange(n_f)[:, None] * (int(partners.facet.max()) + 1) + partners.facet
            else:
                key = np.zeros((0, nq), dtype=np.int64)
            copy_of = (np.full(n_f * nq, -1, dtype=np.int64) if partners.copy_of is None
                       else partners.copy_of.reshape(-1).astype(np.int64))
            own = np.flatnonzero(copy_of < 0)          # points with a slot of their own
            uniq, group = np.unique(key.ravel()[own], return_inverse=True)
            n_g = uniq.size
            order = np.argsort(group, kind="stable")
            counts = np.bincount(group, minlength=n_g)
            starts = (np.cumsum(counts) - counts).astype(np.int64)
            slot = np.empty(group.size, dtype=np.int64)
            slot[order] = np.arange(group.size) - np.repeat(starts, counts)
            nqs = int(counts.max(initial=0))
            first_point = own[order[starts]] if n_g else np.zeros(0, dtype=np.int64)
            group_facet = first_point // nq
            B2 = np.einsum("fqac,fqk->fqakc", R, partners.N2).reshape(n_f * nq, 3, 3 * n_close)
            B = np.zeros((n_g, nqs, 3, 6 * n_close))
            B[group, slot] = np.concatenate([B1.reshape(n_f * nq, 3, 3 * n_close)[own],
                                             B2[own]], axis=2)
            nodes = np.concatenate([nodes1[group_facet],
                                    partners.nodes2.reshape(n_f * nq, n_close)[first_point]],
                                   axis=1)
            self._jump0[:, 0] += partners.gap0.reshape(-1)
            self.n_remote_partners = int(np.sum(partners.remote.reshape(-1)[first_point]))
            self._group_keys = np.stack(
                [group_facet, partners.facet.reshape(-1)[first_point]], axis=1)
            point_slot = np.empty(n_f * nq, dtype=np.int64)
            point_slot[own] = group * nqs + slot
            copies = np.flatnonzero(copy_of >= 0)
            point_slot[copies] = point_slot[copy_of[copies]]
        if partners is None:
            point_slot = np.repeat(groups_of_facet, nq) * nqs + slot
        pair_dofs = (3 * nodes[:, :, None] + np.arange(3)).reshape(n_g, 3 * nodes.shape[1])
        order = np.argsort(pair_dofs, axis=1)
        pair_dofs = np.take_along_axis(pair_dofs, order, axis=1)
        B = np.take_along_axis(B, order[:, None, None, :], axis=3)
        self._n_pair_dofs = B.shape[3]
        self.n_groups, self._nqs = n_g, nqs
        self._B = B.reshape(n_g * nqs, 3, self._n_pair_dofs)
        self._Bf = B.reshape(n_g, nqs * 3, self._n_pair_dofs)  # per-group view for matmul
        self._BfT = np.ascontiguousarray(np.swapaxes(self._Bf, 1, 2))
        self._point_slot = point_slot.astype(np.int64)
        self._own_slot = (np.ones(n_f * nq, dtype=bool) if partners is None or
                          partners.copy_of is None else partners.copy_of.reshape(-1) < 0)
        self._identity_slots = bool(n_g * nqs == n_f * nq and
                                    np.array_equal(point_slot, np.arange(n_f * nq)))
        self._pair_nodes = nodes  # (n_g, n_nodes_pair) global block indices
        self._pair_dofs = pair_dofs  # (n_g, nd) global scalar DOFs
        self.n_points = n_f * nq
        self.n_points_global = self.comm.allreduce(self.n_points, op=MPI.SUM)

    def _to_slots(self, values: np.ndarray) -> np.ndarray:
        """Per-point values (n_pts, ...) laid out in group slots (n_g * nqs, ...), zero in unused
        slots."""
        if self._identity_slots:
            return values
        out = np.zeros((self.n_groups * self._nqs,) + values.shape[1:])
        own = self._own_slot
        out[self._point_slot[own]] = values[own]   # slot-filling copies carry weight 0
        return out

    def _communication(self, bcs, global_dofs=None) -> None:
        """One scatter for every DOF the owned facets touch; Dirichlet rows masked (collective)."""
        self._uniq, inv = np.unique(self._pair_dofs, return_inverse=True)
        self._inv = inv.reshape(self._pair_dofs.shape)
        template = dolfinx.cpp.la.petsc.create_vector(self.V.dofmap.index_map, 3)
        self._template = template
        self._loc = PETSc.Vec().createSeq(self._uniq.size, comm=MPI.COMM_SELF)
        is_from = PETSc.IS().createGeneral(self._uniq.astype(PETSc.IntType), comm=MPI.COMM_SELF)
        self._scatter = PETSc.Scatter().create(template, is_from, self._loc, None)
        self._rows = self._pair_dofs.astype(PETSc.IntType)
        self.set_dirichlet_dofs(global_dofs, bcs)

    def _initial_history(self) -> StatePair:
        """The law's virgin state, checked against the LawState contract (collective)."""
        n = self.n_points
        state, error = None, None
        try:
            state = self.law.initial_state(n)
            if not isinstance(state, LawState):
                raise LawContractError(
                    f"{type(self.law).__name__}.initial_state returned "
                    f"{type(state).__name__}, which lacks plastic_slip, copy() or __len__ "
                    "(rough_contact.interface.contract.LawState)")
            if len(state) != n or np.shape(state.plastic_slip) != (n, 2):
                raise LawContractError(
                    f"{type(self.law).__name__}.initial_state({n}) holds {len(state)} points "
                    f"with plastic_slip of shape {np.shape(state.plastic_slip)}; the contract "
                    f"needs {n} and ({n}, 2)")
        except Exception as exc:  # noqa: BLE001 - re-raised on every rank just below
            error = exc
        raise_on_all_ranks(self.comm, error)
        return StatePair(state)

    def set_dirichlet_dofs(self, global_dofs: np.ndarray | None = None, bcs: Sequence[dolfinx.fem.DirichletBCMetaClass] = ()):
        """Mark DOFs the interface must not assemble into (collective).

        Args:
            global_dofs: global scalar DOF indices owned by this rank (each rank passes its own).
            bcs: dolfinx DirichletBC objects of V (their owned DOFs are added).
        """
        self._dirichlet = (global_dofs, list(bcs))   # re-applied after a re-pairing
        marker = self._template.duplicate()
        marker.set(0.0)
        r0 = marker.getOwnershipRange()[0]
        arr = marker.getArray()
        n_own = arr.size
        for bc in bcs:
            dofs, n_owned_bc = bc.dof_indices()
            dofs = np.asarray(dofs)[:n_owned_bc]
            arr[dofs[dofs < n_own]] = 1.0
        if global_dofs is not None:
            g = np.asarray(global_dofs, dtype=np.int64) - r0
            if np.any((g < 0) | (g >= n_own)):
                raise ValueError(
                    "set_dirichlet_dofs: global_dofs must be owned by the calling rank, got "
                    f"{int(np.sum((g < 0) | (g >= n_own)))} DOFs outside [{r0}, {r0 + n_own})"
                )
            arr[g] = 1.0
        marker.setArray(arr)
        self._scatter.scatter(marker, self._loc, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        fixed = self._loc.getArray()[self._inv] != 0.0
        self._rows = np.where(fixed, -1, self._pair_dofs).astype(PETSc.IntType)
        marker.destroy()

    def sparsity_blocks(self) -> tuple[np.ndarray, np.ndarray]:
        """Global node-level (block size 3) (rows, cols) of every pair's dense block.

        Returns:
            rows, cols: int64 arrays (n_groups, m, m) of global block indices, m = nodes per
            group.
        """
        m = self._pair_nodes.shape[1]
        rows = np.broadcast_to(self._pair_nodes[:, :, None], (self.n_groups, m, m))
        cols = np.broadcast_to(self._pair_nodes[:, None, :], (self.n_groups, m, m))
        return rows, cols

    def create_matrix(self, a) -> PETSc.Mat:
        """A PETSc AIJ matrix with the pattern of the bilinear form ``a`` plus the interface.

        The interface couples DOFs that share no cell (often no rank), so the pattern is
        merged here in global indices; the matrix has dolfinx's layout and local-to-global
        map, so ``dolfinx.fem.petsc.assemble_matrix(A, a, bcs)`` works on it.
        """
        comm = self.comm
        imap = self.V.dofmap.index_map
        bs = 3
        sp = dolfinx.fem.create_sparsity_pattern(a)
        sp.assemble()
        n_loc = imap.size_local
        r0 = imap.local_range[0]
        graph = sp.graph
        cm = sp.column_index_map()
        col_l2g = np.concatenate(
            [np.arange(*cm.local_range, dtype=np.int64), cm.ghosts.astype(np.int64)]
        )
        off = graph.offsets
        bulk_rows = np.repeat(np.arange(n_loc, dtype=np.int64) + r0, np.diff(off[: n_loc + 1]))
        bulk_cols = col_l2g[graph.array[: off[n_loc]]]
        n_glob = imap.size_global
        # interface entries, sent to the rank owning the row
        rows, cols = self.sparsity_blocks()
        key = np.unique(rows.ravel() * n_glob + cols.ravel())
        ranges = np.array(comm.allgather(imap.local_range[0]) + [n_glob])
        dest = np.searchsorted(ranges, key // n_glob, side="right") - 1
        order = np.argsort(dest, kind="stable")
        key = key[order]
        send_counts = np.bincount(dest, minlength=comm.size).astype(np.int64)
        recv_counts = np.array(comm.alltoall(send_counts.tolist()), dtype=np.int64)
        recv = np.empty(recv_counts.sum(), dtype=np.int64)
        comm.Alltoallv([key, send_counts, MPI.INT64_T], [recv, recv_counts, MPI.INT64_T])
        key = np.unique(np.concatenate([bulk_rows * n_glob + bulk_cols, recv]))
        nrow = key // n_glob - r0
        ncol = key % n_glob
        indptr_n = np.concatenate([[0], np.cumsum(np.bincount(nrow, minlength=n_loc))])
        # expand the node pattern to scalar rows: row bs*r+i has cols bs*c+j, c in row r
        seg = (bs * ncol[:, None] + np.arange(bs)).ravel()
        L = bs * np.diff(indptr_n)
        lens = np.repeat(L, bs)
        indptr = np.concatenate([[0], np.cumsum(lens)])
        within = np.arange(indptr[-1]) - np.repeat(indptr[:-1], lens)
        start = np.repeat(np.repeat(bs * indptr_n[:-1], bs), lens)
        indices = seg[start + within]
        A = PETSc.Mat().create(comm=comm)
        A.setSizes(((bs * n_loc, bs * n_glob), (bs * n_loc, bs * n_glob)), bsize=bs)
        A.setType(PETSc.Mat.Type.AIJ)
        A.setPreallocationCSR(
            (indptr.astype(PETSc.IntType), indices.astype(PETSc.IntType))
        )
        l2g = np.concatenate(
            [np.arange(*imap.local_range, dtype=np.int64), imap.ghosts.astype(np.int64)]
        )
        lgmap = PETSc.LGMap().create(l2g.astype(PETSc.IntType), bsize=bs, comm=MPI.COMM_SELF)
        A.setLGMap(lgmap, lgmap)
        A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
        A.zeroEntries()
        if self.sliding == "moderate":     # the (first facet, partner facet) blocks it holds
            self._matrix_keys = {tuple(k) for k in self._group_keys.tolist()}
        return A

    # ------------------------------------------------------------------ moderate sliding
    def update_pairing(self, u: dolfinx.fem.Function) -> bool:
        """Project the first surface's points again, on the surfaces deformed by ``u``
        (``sliding="moderate"``; collective; ``load_path`` calls it after every converged
        increment).

        Kinematics (decision): every point keeps its place on the first surface, its frame
        (the reference normal and axes: small rotations) and its law state. Its current
        position x1 = X1 + u1 is projected along its normal onto the second surface at its
        current position X2 + u2 (exact on P2 faces). The new partner carries the jump on:
        the normal gap becomes the geometric distance found by the projection (the surface
        under the point may have changed), the tangential jump is kept continuous (the
        friction law's elastic slip and plastic slip are unaffected by the change of partner);
        from then on tangential jump increments are relative displacements against the new
        partner. With small sliding instead the point stays bound to the material point of
        the other body it faced at set-up.

        Returns:
            True when the (first facet, partner facet) blocks changed: the caller rebuilds the
            matrices (``ContactProblem.rebuild_matrices``) so that the Jacobian pattern is
            exactly the current blocks' (a resumed run then reproduces the uninterrupted one).

        Raises:
            ValueError: points that slid off the second surface (no partner within the
                search radius), on every rank.
        """
        if self.sliding != "moderate":
            raise ValueError("update_pairing needs sliding = 'moderate'")
        msh = self.V.mesh
        u_arr = u.x.array.reshape(-1, 3)
        n_f, nq, n_close = self._N1.shape
        jump_old = self.jump(u)
        x1 = self._x + np.einsum("fqk,fki->fqi", self._N1,
                                 u_arr[self._local_nodes1]).reshape(-1, 3)
        sec = self._second
        u2 = self.comm.allgather(u_arr[sec.own_local_nodes])
        u2 = np.concatenate(u2).reshape(-1, n_close, 3) if u2 else np.zeros((0, n_close, 3))
        cell_x = sec.surface.cell_x.copy()
        rows = np.arange(cell_x.shape[0])[:, None]
        cell_x[rows, sec.closure[sec.local_facet]] += u2   # Lagrange: facet = its closure
        nv = sec.vertex_x.shape[1]
        surface = _facet_set(msh, cell_x, sec.local_facet, sec.vertex_x + u2[:, :nv])
        proj = project_points(x1, self._R[:, 0, :], surface, _cmap_element(msh),
                              self.search_radius)
        self._check_partners(proj, x1, self.search_radius, self.second_tag,
                             after="after sliding: ")
        return self._set_pairing(proj, jump_old, u)

    def pairing_state(self) -> Optional[dict]:
        """The current partners and jump offsets (moderate sliding; for checkpoints), or None
        for small sliding (the pairing is rebuilt identically at set-up)."""
        if self.sliding != "moderate":
            return None
        return dict(projection=self._projection, jump0=self._jump0.copy())

    def restore_pairing(self, state: Optional[dict], u: dolfinx.fem.Function) -> bool:
        """Reinstate :meth:`pairing_state` (collective). Returns True: rebuild the matrices."""
        if state is None or state["projection"] is None:
            return False
        self._set_pairing(state["projection"], None, u)
        self._jump0 = np.array(state["jump0"])
        return True

    def _set_pairing(self, proj, jump_old, u) -> bool:
        n_f, nq, _ = self._N1.shape
        partners = self._partners(proj, (n_f, nq))
        moved = self.comm.allreduce(int(np.any(partners.facet.reshape(-1) !=
                                               self._partner_facet)), op=MPI.SUM)
        self._jump0 = np.zeros((n_f * nq, 3))
        self._jump_operator(self._R_full, self._N1, self._nodes1,
                            replace(partners, gap0=np.zeros((n_f, nq))))
        global_dofs, bcs = self._dirichlet
        self._communication(bcs, global_dofs)
        if jump_old is not None:
            raw = self._jump_of(self._pair_values(u))
            jump0 = jump_old - raw                  # tangential jump continuous
            jump0[:, 0] = proj.distance - raw[:, 0]  # normal: the geometric gap now
            self._jump0 = jump0
        self._projection = proj
        self._partner_facet = partners.facet.reshape(-1).copy()
        self._cache_valid = False
        self._last = None
        if moved:
            self.n_repairs += 1
        # the pattern follows the current blocks exactly (not their history): a resumed run
        # then assembles into the same pattern as the uninterrupted one, bit for bit
        changed = {tuple(k) for k in self._group_keys.tolist()} != self._matrix_keys
        return bool(self.comm.allreduce(changed, op=MPI.LOR))

    # ------------------------------------------------------------------ evaluation
    def _pair_values(self, u: Union[dolfinx.fem.Function, PETSc.Vec]) -> np.ndarray:
        x = u if isinstance(u, PETSc.Vec) else u.vector
        self._scatter.scatter(x, self._loc, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        return self._loc.getArray(readonly=True)[self._inv]

    def jump(self, u: Union[dolfinx.fem.Function, PETSc.Vec]) -> np.ndarray:
        """Local jump [g, s_x, s_y] (n_pts, 3) [mm] at displacement u (Function or PETSc Vec)."""
        return self._jump_of(self._pair_values(u))

    def _jump_of(self, u_pair: np.ndarray) -> np.ndarray:
        # batched matmul per group: (n_g, nqs*3, nd) @ (n_g, nd, 1)
        jump = (self._Bf @ u_pair[:, :, None]).reshape(-1, 3)
        if not self._identity_slots:
            jump = jump[self._point_slot]
        return jump + self._jump0

    def evaluate(self, u: Union[dolfinx.fem.Function, PETSc.Vec]) -> LawResult:
        """Evaluate the law at u (collective); cached while u's pair values do not change.

        The law is called once per new u on all points of this rank; the trial state and the
        dissipation increment go to ``history`` (committed by :meth:`commit`).

        Raises:
            ConvergenceError: on every rank, if any rank met a non-finite jump, a non-finite
                traction or tangent, or a ConvergenceError of the law.
            LawContractError: the first result breaks the contract (naming the field).
            Exception: any other exception of the law, with its type on the failing rank and
                as a RuntimeError naming it on the others.
        """
        u_pair = self._pair_values(u)
        hit = self._cache_valid and np.array_equal(u_pair, self._last_u)
        if self.comm.allreduce(hit, op=MPI.LAND):  # ranks must agree: collectives follow
            return self._last
        jump = self._jump_of(u_pair)
        res, error = None, None
        try:
            self._check_finite("jump", jump, np.isfinite(jump).all(axis=1))
            res = self.law.evaluate(jump, self.history.committed)
            if not self._result_checked:
                _check_result(self.law, res, self.n_points)
            finite = np.isfinite(res.traction).all(axis=1) & np.isfinite(res.tangent).all(
                axis=(1, 2))
            self._check_finite("traction/tangent returned by the law", jump, finite)
        except Exception as exc:  # noqa: BLE001 - re-raised on every rank just below
            error = exc
        raise_on_all_ranks(self.comm, error)
        self._result_checked = True
        self.history.update(res)
        self._last_u, self._last, self._last_jump = u_pair.copy(), res, jump
        self._cache_valid = True
        return res

    def _check_finite(self, what: str, jump: np.ndarray, finite: np.ndarray) -> None:
        """Raise ConvergenceError (this rank) if ``finite`` (n_pts,) is False somewhere: a
        diverging global iterate, which a smaller load increment may cure."""
        if finite.all():
            return
        bad = np.flatnonzero(~finite)
        raise ConvergenceError(
            f"non-finite {what} at {bad.size} of {self.n_points} interface points of rank "
            f"{self.comm.rank}, e.g. at x = {self._x[bad[0]].tolist()} mm "
            f"(jump {jump[bad[0]].tolist()} mm)")

    def assemble_residual(self, u: Union[dolfinx.fem.Function, PETSc.Vec], b: PETSc.Vec) -> None:
        """Add int B^T t dA to b (global PETSc Vec of V's layout) and assemble b (collective)."""
        res = self.evaluate(u)
        tw = self._to_slots(res.traction * self._weights[:, None])
        r = self._BfT @ tw.reshape(self.n_groups, 3 * self._nqs, 1)  # (n_g, nd, 1)
        rows = self._rows.ravel()
        keep = rows >= 0
        if np.any(keep):
            b.setValues(rows[keep], r.ravel()[keep], addv=PETSc.InsertMode.ADD_VALUES)
        b.assemblyBegin()
        b.assemblyEnd()

    def assemble_jacobian(self, u: Union[dolfinx.fem.Function, PETSc.Vec], A: PETSc.Mat) -> None:
        """Add int B^T D B dA to A (collective). Flushes A first; the caller calls A.assemble()."""
        res = self.evaluate(u)
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        if self.n_groups == 0:  # setValuesRCV with zero rows dies with SIGFPE
            return
        tangent = res.tangent
        if isinstance(self.law, NewtonTangentLaw):   # Newton-step tangent (residual unchanged)
            tangent, self._newton_memo = self.law.newton_tangent(
                self._last_jump, self.history.committed, res, self._newton_memo)
        D = self._to_slots(tangent * self._weights[:, None, None])
        DB = D @ self._B  # (n_g * nqs, 3, nd)
        K = self._BfT @ DB.reshape(self._Bf.shape)  # (n_g, nd, nd), batched BLAS
        rows = self._rows
        A.setValuesRCV(rows, rows, K, addv=PETSc.InsertMode.ADD_VALUES)

    # ------------------------------------------------------------------ history
    def commit(self, u: Union[dolfinx.fem.Function, PETSc.Vec, None] = None) -> None:
        """Accept the trial state of the last evaluation (after a converged increment).

        Args:
            u: if given, the law is first evaluated at u (the converged displacement).
        """
        if u is not None:
            self.evaluate(u)
        if self.augmentation() is not None:   # the multipliers this increment started from
            self._multipliers_before = (self._augment_base if self._augment_base is not None
                                        else self.history.committed)
        self.history.commit()
        self._cache_valid = False  # a new committed state: never reuse the old evaluation
        self._newton_memo = None
        self._augment_base = None

    def predictor_state(self):
        """What :meth:`extrapolate_multipliers` needs from the past (the committed state the
        last converged increment started from, or None); a checkpoint stores it."""
        return self._multipliers_before

    def restore_predictor_state(self, state) -> None:
        """Set what :meth:`predictor_state` returned (resuming a checkpoint)."""
        if state is not None and (not isinstance(state, LawState)
                                  or len(state) != len(self.history.committed)):
            raise ValueError(f"predictor state ({type(state).__name__}) must be None or a "
                             f"LawState of {len(self.history.committed)} points")
        self._multipliers_before = state

    def extrapolate_multipliers(self, ratio: float) -> bool:
        """Secant predictor of an augmented-Lagrangian law's multipliers (no communication):
        lambda_n + ratio (lambda_n - lambda_{n-1}), the committed state's multipliers and those
        the last converged increment started from. :meth:`revert` undoes it. Returns whether
        anything was done (not for a plain law, nor before the second converged increment)."""
        if self.augmentation() is None or self._multipliers_before is None:
            return False
        check_scalar("ratio", ratio)
        self._replace_multipliers(
            self.law.extrapolate(self.history.committed, self._multipliers_before, ratio))
        return True

    def _replace_multipliers(self, new) -> None:
        """Make ``new`` the committed state of this increment (multipliers changed), keeping
        the state the increment started from for :meth:`revert`; drop the trial state."""
        if self._augment_base is None:
            self._augment_base = self.history.committed
        self.history.restore(new, self.history.dissipated)
        self._last = None
        self._cache_valid = False
        self._newton_memo = None

    def revert(self) -> None:
        """Discard the trial state (failed increment, before a cutback), and the multiplier
        updates of the increment if the law is an augmented-Lagrangian one."""
        if self._augment_base is not None:
            self.history.restore(self._augment_base, self.history.dissipated)
            self._augment_base = None
        self.history.revert()
        self._last = None
        self._cache_valid = False
        self._newton_memo = None

    def augmentation(self) -> Optional[AugmentationControl]:
        """The law's augmented-Lagrangian control (None for a plain law: no multiplier loop)."""
        if isinstance(self.law, AugmentedLagrangianLaw):
            return self.law.augmentation()
        return None

    def augment(self, tolerance: float) -> tuple[float, bool]:
        """One Uzawa update of the multipliers from the last evaluation (collective).

        The relative change is the largest multiplier change over all points and ranks divided
        by the largest traction magnitude |t| (0 if no point carries any). If it exceeds
        ``tolerance`` the committed state takes the new multipliers (the trial state is
        dropped; the next Newton solve uses them); otherwise nothing changes and the trial state
        can be committed. :meth:`revert` undoes the updates of the current increment.

        Returns:
            (relative change, whether the multipliers were updated).

        Raises:
            ValueError: the law has no augmented-Lagrangian control, or the interface was not
                evaluated since the last commit/revert.
        """
        if self.augmentation() is None:
            raise ValueError(f"the law {type(self.law).__name__} is not an augmented-Lagrangian "
                             "law (AugmentedLagrangianLaw with augmentation() not None)")
        res = self._result()
        new, change = self.law.augment(self.history.committed, res)
        top = np.zeros(2)
        if change.size:
            top[:] = change.max(), np.linalg.norm(res.traction, axis=1).max()
        self.comm.Allreduce(MPI.IN_PLACE, top, op=MPI.MAX)
        top_change, top_traction = top
        rel = top_change / top_traction if top_traction > 0.0 else 0.0
        if rel <= tolerance:
            return rel, False
        self._replace_multipliers(new)
        return rel, True

    def begin_solve(self) -> None:
        """Forget what the previous Newton solve's Jacobians remembered (a law's
        ``newton_tangent`` memo, e.g. the slip directions of ``SoftplusPenalty``); the SNES
        wrapper calls it before every solve."""
        self._newton_memo = None

    # ------------------------------------------------------------------ output
    def _result(self) -> LawResult:
        if self._last is None:
            raise ValueError("the interface has not been evaluated since the last commit/revert")
        return self._last

    def contact_force(self) -> np.ndarray:
        """(3,) force on the FIRST body's surface in global axes [N] (collective)."""
        res = self._result()
        f = np.einsum("pai,pa,p->i", self._R, res.traction, self._weights)
        return self.comm.allreduce(f, op=MPI.SUM)

    def interface_stiffness(self) -> np.ndarray:
        """(3,) the interface's tangent stiffness summed over its area, in local axes
        (normal, x, y): int dt_i/djump_i dA [N/mm] at the last evaluation (collective). For a
        flat joint these are its normal and tangential interface stiffnesses (the bodies'
        compliance not included)."""
        res = self._result()
        k = np.einsum("pii,p->i", res.tangent, self._weights)
        return self.comm.allreduce(k, op=MPI.SUM)

    def real_contact_area(self) -> float:
        """int A/A0 dA over the interface [mm^2] (collective)."""
        res = self._result()
        return self.comm.allreduce(float(np.dot(res.area_fraction, self._weights)), op=MPI.SUM)

    def nominal_area(self) -> float:
        """Area of the first contact surface [mm^2] (collective)."""
        return self.comm.allreduce(float(self._weights.sum()), op=MPI.SUM)

    def dissipation(self) -> float:
        """Committed accumulated frictional dissipation int D dA [N mm] (collective)."""
        return self.comm.allreduce(float(np.dot(self.history.dissipated, self._weights)),
                                   op=MPI.SUM)

    def mean_normal(self) -> np.ndarray:
        """(3,) area-weighted mean unit normal of the first surface (towards the second body),
        global axes (collective)."""
        n = self.comm.allreduce(np.einsum("pi,p->i", self._R[:, 0, :], self._weights),
                                op=MPI.SUM)
        norm = np.linalg.norm(n)
        return n / norm if norm > 0 else n

    def n_contact(self) -> int:
        """Global number of points in contact (p > 0) at the last evaluation (collective, one
        allreduce: cheap enough for every Jacobian)."""
        return self.comm.allreduce(int((self._result().contact & self._own_slot).sum()),
                                   op=MPI.SUM)

    def summary(self) -> InterfaceSummary:
        """Global figures after the last evaluation (collective: two allreduces)."""
        res = self._result()
        w = self._weights
        own = self._own_slot    # counts skip the mortar pairing's slot-filling copies
        force = np.einsum("pai,pa,p->i", self._R, res.traction, w)
        sums = np.concatenate([force, [
            float(np.dot(res.area_fraction, w)), float(w.sum()), float(w[res.contact].sum()),
            float(w[res.slipping].sum()), float(np.dot(self.history.dissipated, w)),
            float((res.contact & own).sum()), float((res.slipping & own).sum()),
            0.0 if res.beyond_validity is None else float((res.beyond_validity & own).sum()),
            float(own.sum())]])
        sums = self.comm.allreduce(sums, op=MPI.SUM)
        slip = np.linalg.norm(self._last_jump[:, 1:], axis=1)
        plastic = np.linalg.norm(self.history.trial.plastic_slip, axis=1)
        maxima = np.array([slip.max(initial=0.0), plastic.max(initial=0.0)])
        self.comm.Allreduce(MPI.IN_PLACE, maxima, op=MPI.MAX)
        return InterfaceSummary(
            n_points=int(sums[11]), n_contact=int(sums[8]), n_slipping=int(sums[9]),
            contact_force=sums[:3], real_area=float(sums[3]), nominal_area=float(sums[4]),
            contact_area=float(sums[5]), slipping_area=float(sums[6]),
            max_slip=float(maxima[0]), max_plastic_slip=float(maxima[1]),
            dissipation=float(sums[7]), n_beyond_validity=int(sums[10]))

    def slip_stats(self) -> InterfaceSummary:
        """Same as :meth:`summary` (the name older callers use)."""
        return self.summary()

    @property
    def facets(self) -> np.ndarray:
        """(n_facets,) local indices of this rank's owned first-surface facets, in point order:
        point i lies on facet ``facets[i // n_qp]`` (read-only)."""
        return _read_only(self._facets1)

    def local_frames(self) -> np.ndarray:
        """(n_pts, 3, 3) local axes per point: rows n, x, y in global components (read-only)."""
        return _read_only(self._R)

    def point_coordinates(self) -> np.ndarray:
        """(n_pts, 3) reference coordinates of this rank's interface points [mm]."""
        return self._x

    def point_weights(self) -> np.ndarray:
        """(n_pts,) area represented by each of this rank's points [mm^2]."""
        return self._weights

    def point_fields(self) -> PointFields:
        """This rank's point fields at the last evaluation (see PointFields)."""
        res = self._result()
        jump = self._last_jump
        return PointFields(
            pressure=-res.traction[:, 0],
            shear=res.traction[:, 1:].copy(),
            area_fraction=np.asarray(res.area_fraction),
            gap=jump[:, 0],
            slip=jump[:, 1:],
            plastic_slip=np.array(self.history.trial.plastic_slip, dtype=float),
            dissipation=self.history.dissipated.copy(),
            contact=np.asarray(res.contact),
            slipping=np.asarray(res.slipping),
            weight=self._weights,
        )


def _check_arguments(V, law, first_tag, second_tag, rigid_plane, quadrature_degree,
                     grain_direction, match_tolerance, quadrature="gauss"
                     ) -> tuple[np.ndarray, int]:
    """Validate ContactInterface's arguments; return the grain direction (3,) and the degree."""
    missing = [m for m in ("initial_state", "evaluate") if not callable(getattr(law, m, None))]
    if missing or not isinstance(law, InterfaceLawProtocol):
        raise TypeError(
            f"law {type(law).__name__} does not satisfy InterfaceLawProtocol "
            f"(rough_contact.interface.contract): missing method(s) {', '.join(missing)}")
    msh = V.mesh
    if msh.topology.dim != 3 or msh.topology.cell_type not in _CELLS:
        raise ValueError(
            "ContactInterface needs a tetrahedral or hexahedral 3D mesh, got "
            f"{msh.topology.cell_type}"
        )
    bs = V.dofmap.index_map_bs
    element = V.element.basix_element
    if bs != 3 or element.degree not in (1, 2) or element.family != basix.ElementFamily.P:
        raise ValueError(
            f"V must be a vector Lagrange space of degree 1 or 2 with 3 components, got "
            f"block size {bs}, degree {element.degree}"
        )
    if V.element.needs_dof_transformations:
        raise ValueError("V needs DOF transformations on facets (degree >= 3): not supported")
    if msh.geometry.cmap.degree not in (1, 2):
        raise ValueError(f"geometry degree {msh.geometry.cmap.degree} not supported (1 or 2)")
    if second_tag is not None and second_tag == first_tag:
        raise ValueError(f"first_tag and second_tag are both {first_tag}")
    if second_tag is not None and rigid_plane is not None:
        raise ValueError("give either second_tag or rigid_plane, not both")
    degree = check_scalar("quadrature_degree", quadrature_degree, lo=0, lo_open=False)
    if degree != int(degree):
        raise ValueError(f"quadrature_degree = {quadrature_degree!r} is invalid: it must be an "
                         "integer >= 0")
    check_scalar("match_tolerance", match_tolerance, lo=0.0)
    if quadrature not in ("gauss", "vertex"):
        raise ValueError(f"quadrature = {quadrature!r} is invalid: it must be 'gauss' or 'vertex'")
    if quadrature == "vertex" and element.degree != 1:
        raise ValueError(f"quadrature = 'vertex' needs a degree-1 space (P1/Q1), got degree "
                         f"{element.degree}: use a Gauss rule for P2/Q2")
    grain = np.asarray(grain_direction, dtype=float)
    if grain.shape != (3,) or not np.all(np.isfinite(grain)) or np.linalg.norm(grain) == 0:
        raise ValueError(f"grain_direction = {grain_direction!r} must be a nonzero 3-vector")
    return grain, int(degree)


def _check_result(law, res, n: int) -> None:
    """The full contract check of a law's result (done on the first evaluation)."""
    if not isinstance(res, LawResult):
        raise LawContractError(
            f"{type(law).__name__}.evaluate returned {type(res).__name__}; the contract needs "
            "rough_contact.interface.contract.LawResult")
    res.check(n)


def _facet_connectivity(msh) -> int:
    """Create facet-cell connectivities; return the number of owned facets."""
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim, tdim - 1)
    return msh.topology.index_map(tdim - 1).size_local


def _facet_set(msh, cell_x: np.ndarray, local_facet: np.ndarray,
               vertex_x: np.ndarray) -> SecondSurface:
    """Facets as a :class:`rough_contact.fem.pairing.SecondSurface` (geometry for Newton)."""
    cell = _basix_cell(msh)
    ref_facets = np.array(basix.topology(cell)[2])
    ref_x = np.asarray(basix.geometry(cell), dtype=float)
    fv = ref_x[ref_facets[np.asarray(local_facet, dtype=np.int64)]]  # (n, nv, 3)
    return SecondSurface(
        cell_x=cell_x, v0=fv[:, 0], tangents=np.stack([fv[:, 1] - fv[:, 0],
                                                       fv[:, 2] - fv[:, 0]], axis=2),
        ref_normal=basix.cell.facet_outward_normals(cell)[np.asarray(local_facet, np.int64)],
        triangle=ref_facets.shape[1] == 3, centroid=vertex_x.mean(axis=1))


@dataclass(frozen=True)
class _GatheredSurface:
    """The second contact surface, all-gathered on every rank (for non-matching pairing).

    Attributes:
        surface: its facet geometry (:class:`rough_contact.fem.pairing.SecondSurface`).
        owner: (n2,) owning rank of each facet.
        local_facet: (n2,) local facet index in its cell.
        nodes: (n2, n_close) global block indices of each facet's closure DOFs.
        vertex_x: (n2, nv, 3) vertex coordinates.
        closure: (n_lf, n_close) closure DOFs of every local facet of the element.
        own_local_nodes: (n_own, n_close) local block indices of the closure DOFs of this
            rank's facets (they come first-to-last in rank order in the gathered arrays).
    """

    surface: SecondSurface
    owner: np.ndarray
    local_facet: np.ndarray
    nodes: np.ndarray
    vertex_x: np.ndarray
    closure: np.ndarray
    own_local_nodes: np.ndarray

    @classmethod
    def create(cls, V, facet_tags, tag: int, n_owned_facets: int) -> _GatheredSurface:
        comm = V.mesh.comm
        geo = _FacetGeometry(V, _owned_tagged_facets(facet_tags, tag, n_owned_facets, comm))
        n_close = geo.closure.shape[1]
        gathered = comm.allgather((geo.cell_nodes_x, geo.local_facet, geo.global_nodes,
                                   geo.vertex_x))
        owner = np.concatenate(
            [np.full(g[1].size, r, dtype=np.int64) for r, g in enumerate(gathered)])
        lf = np.concatenate([g[1] for g in gathered]).astype(np.int64)
        vx = np.concatenate([g[3] for g in gathered])
        return cls(surface=_facet_set(V.mesh, np.concatenate([g[0] for g in gathered]), lf, vx),
                   owner=owner, local_facet=lf,
                   nodes=np.concatenate([g[2] for g in gathered]).reshape(-1, n_close),
                   vertex_x=vx, closure=geo.closure,
                   own_local_nodes=np.asarray(geo.local_nodes, dtype=np.int64))


@dataclass(frozen=True)
class _Partners:
    """The second surface seen from every point of the first one (n_f facets x nq points).

    Attributes:
        N2: (n_f, nq, n_close) partner facet's closure basis values at the partner point.
        nodes2: (n_f, nq, n_close) global block indices of the partner facet's closure DOFs.
        facet: (n_f, nq) partner facet id (an index into the gathered second surface).
        remote: (n_f, nq) bool: the partner facet is owned by another rank.
        gap0: (n_f, nq) initial normal gap [mm] (0 for conforming pairs).
        copy_of: (n_f, nq) or None: for slot-filling points (weight 0, see the mortar
            pairing) the index of the point they repeat (-1 for a point of its own).
    """

    N2: np.ndarray
    nodes2: np.ndarray
    facet: np.ndarray
    remote: np.ndarray
    gap0: np.ndarray
    copy_of: Optional[np.ndarray] = None


@dataclass(frozen=True)
class _FacetRule:
    """Facet quadrature on every local facet of the reference cell.

    Attributes:
        nq: points per facet.
        weights: (nq,) reference facet weights.
        lam: (nq, nv) vertex weights of the points: barycentric (triangle) or bilinear
            (quadrilateral). A point of the shared surface has the same weights on both sides
            (up to the vertex permutation), so they carry the partner's reference coordinates.
        vertices: (n_lf, nv, 3) reference coordinates of each local facet's vertices.
        points: (n_lf, nq, 3) the points in reference cell coordinates, per local facet.
        tangents: (n_lf, 3, 2) reference tangents of each local facet.
        normals: (n_lf, 3) reference outward normals.
    """

    nq: int
    weights: np.ndarray
    lam: np.ndarray
    vertices: np.ndarray
    points: np.ndarray
    tangents: np.ndarray
    normals: np.ndarray

    @classmethod
    def create(cls, msh, degree: int, vertex: bool = False) -> _FacetRule:
        """Gauss rule of ``degree`` on the reference facet, or (``vertex``) its vertices with
        equal weights (exact for linear functions on triangles, bilinear ones on
        quadrilaterals: the P1/Q1 facet fields)."""
        cell = _basix_cell(msh)
        facet_cell = _CELLS[msh.topology.cell_type][1]
        ref_facets = np.array(basix.topology(cell)[2])  # (n_lf, nv)
        if vertex:
            xi = np.asarray(basix.geometry(facet_cell), dtype=float)
            area = 0.5 if facet_cell == basix.CellType.triangle else 1.0
            w_ref = np.full(len(xi), area / len(xi))
        else:
            xi, w_ref = basix.make_quadrature(facet_cell, degree)
        lam = _vertex_weights(facet_cell, xi)  # (nq, nv)
        fv_ref = basix.geometry(cell)[ref_facets]  # (n_lf, nv, 3)
        X_lf = np.einsum("qi,fid->fqd", lam, fv_ref)  # (n_lf, nq, 3) points per local facet
        T_lf = np.stack([fv_ref[:, 1] - fv_ref[:, 0], fv_ref[:, 2] - fv_ref[:, 0]], axis=2)
        N_lf = basix.cell.facet_outward_normals(cell)  # (n_lf, 3)
        return cls(w_ref.size, w_ref, lam, fv_ref, X_lf, T_lf, N_lf)


_CELLS = {
    dolfinx.mesh.CellType.tetrahedron: (basix.CellType.tetrahedron, basix.CellType.triangle),
    dolfinx.mesh.CellType.hexahedron: (basix.CellType.hexahedron, basix.CellType.quadrilateral),
}


# surface nodes per surface facet of a large surface mesh (triangles: V ~ F / 2, E ~ 3F / 2;
# quadrilaterals: V ~ F, E ~ 2F), by (cell type, element degree)
_NODES_PER_FACET = {
    (dolfinx.mesh.CellType.tetrahedron, 1): 0.5, (dolfinx.mesh.CellType.tetrahedron, 2): 2.0,
    (dolfinx.mesh.CellType.hexahedron, 1): 1.0, (dolfinx.mesh.CellType.hexahedron, 2): 4.0,
}


def _warn_overconstrained(law, n_points: int, cell_type, element_degree: int,
                          rule_degree: int) -> None:
    """Warn when an augmented-Lagrangian law would enforce its constraints exactly at more
    points per facet than there are surface nodes per facet (they lock: the multiplier
    iteration stalls, docs/coulomb.md)."""
    if not (isinstance(law, AugmentedLagrangianLaw) and law.augmentation() is not None):
        return
    nodes = _NODES_PER_FACET.get((cell_type, element_degree))
    if nodes is None or n_points <= nodes:
        return
    fix = ("use quadrature='vertex'" if element_degree == 1 else
           f"use a facet rule of at most {int(nodes)} point(s) per facet (quadrature_degree=1 "
           "on triangles), or a P1/Q1 mesh with the vertex rule")
    warnings.warn(
        f"an augmented-Lagrangian law enforces its constraints exactly at every point: the "
        f"Gauss rule of degree {int(rule_degree)} puts {n_points} points on each facet, about "
        f"{n_points / nodes:g} times the surface nodes of a degree-{element_degree} mesh; the "
        "constraints lock and the multiplier iteration may not converge where contact or stick "
        f"ends (docs/coulomb.md); {fix}", UserWarning, stacklevel=3)


def _read_only(a: np.ndarray) -> np.ndarray:
    view = a.view()
    view.flags.writeable = False
    return view


def _basix_cell(msh) -> basix.CellType:
    return _CELLS[msh.topology.cell_type][0]


def _cmap_element(msh):
    # dolfinx's coordinate element is the basix Lagrange element of the geometry degree;
    # for degree <= 2 all Lagrange variants have the same nodes.
    return basix.create_element(
        basix.ElementFamily.P, _basix_cell(msh), msh.geometry.cmap.degree,
        basix.LagrangeVariant.equispaced,
    )


def _vertex_weights(facet_cell, xi: np.ndarray) -> np.ndarray:
    """(nq, nv) P1/Q1 vertex shape functions of the reference facet at points xi (nq, 2)."""
    a, b = xi[:, 0], xi[:, 1]
    if facet_cell == basix.CellType.triangle:
        return np.column_stack([1.0 - a - b, a, b])
    return np.column_stack([(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b])


def _plane(rigid_plane: RigidPlane) -> tuple[np.ndarray, np.ndarray]:
    try:
        point, normal = rigid_plane
    except (TypeError, ValueError):
        raise ValueError(f"rigid_plane = {rigid_plane!r} must be (point (3,), normal (3,))")
    point = np.asarray(point, dtype=float)
    normal = np.asarray(normal, dtype=float)
    if point.shape != (3,) or normal.shape != (3,) or not np.all(np.isfinite(normal)):
        raise ValueError(f"rigid_plane = {rigid_plane!r} must be (point (3,), normal (3,))")
    nn = np.linalg.norm(normal)
    if nn == 0:
        raise ValueError("rigid_plane normal must be nonzero")
    return point, normal / nn
