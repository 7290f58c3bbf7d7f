"""Set-up steps several scenes share (and the FE tests that build the same set-ups).

``check_mesh_arguments``: the mesh arguments of a scene (sizes [mm] > 0, element order 1 or 2).
``clamped_pair``: a two-body scene's bottom clamped and the contact interface of its pair.
``preload_then_drive``: the problem of a body pressed onto the other by a normal force on its
top face (channel "preload") while that face is displaced tangentially (a prescribed
displacement on its own channel): the fretting, bolt-head and load-program set-ups.

Units: mm, N, MPa.
"""

from __future__ import annotations

from rough_contact.fem.boundary import fix
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, PrescribedDisplacement, SurfaceLoad
from rough_contact.scenes.defaults import SEATING_STIFFNESS
from rough_contact.validation import check_scalar

__all__ = ["check_mesh_arguments", "check_points_basis", "clamped_pair", "preload_then_drive"]


def check_mesh_arguments(order, **sizes) -> None:
    """Raise ``ValueError`` naming the first of ``sizes`` [mm] that is not > 0, or an ``order``
    other than 1 or 2."""
    for name, value in sizes.items():
        check_scalar(name, value, lo=0.0, unit="mm")
    if order not in (1, 2):
        raise ValueError(f"order = {order!r} is invalid: it must be 1 or 2")


def clamped_pair(scene, V, law, **options) -> tuple:
    """The facets ``"bottom"`` of ``scene`` clamped, and the contact interface of its contact
    pair with ``law`` (``options``: further keywords of ``ContactInterface``). Collective.

    Returns:
        (the clamp, a DirichletBC; the ``ContactInterface``).
    """
    clamp = fix(V, scene.facet_tags, scene.tag("bottom"))
    first, second = scene.contact_pair
    return clamp, ContactInterface(V, scene.facet_tags, first, second, law=law, bcs=[clamp],
                                   **options)


def preload_then_drive(scene, V, material, clamp, interface, top: int, force: float,
                       drive: float, channel: str, programs: dict) -> ContactProblem:
    """The problem of the body on the first contact surface pressed by ``force`` [N] (along -z,
    channel "preload") on its facets ``top``, which are displaced by ``drive`` [mm] along x
    (channel ``channel``); the other body held by ``clamp``. The first surface is seated
    (``SEATING_STIFFNESS``) while it carries no pressure. ``programs``: channel -> load factor
    of the time. Collective."""
    return ContactProblem(
        V, material, [clamp], [SurfaceLoad(top, force=(0.0, 0.0, -force), channel="preload")],
        facet_tags=scene.facet_tags, interface=interface, seating_tag=interface.first_tag,
        seating_stiffness=SEATING_STIFFNESS,
        prescribed=[PrescribedDisplacement(top, (drive, 0.0, 0.0), (0,), channel=channel)],
        programs=programs)


def check_points_basis(points, basis):
    """The interface points and the nodal set's basis: refused with the valid values (the
    same check on every rank, before any collective call)."""
    if points not in ("quadrature", "nodal"):
        raise ValueError(f"points = {points!r} is invalid: 'quadrature' or 'nodal'")
    if basis not in ("standard", "dual", "dual_quadratic"):
        raise ValueError(f"basis = {basis!r} is invalid: 'standard' (the vertex functions), "
                         "'dual' (their biorthogonal basis) or 'dual_quadratic' (every node "
                         "of P2/Q2, the quadratic dual basis)")
    if basis != "standard" and points != "nodal":
        raise ValueError(f"basis = {basis!r} is invalid with points = {points!r}: the basis "
                         "weighs the nodal set's vertex jumps, use points='nodal' (or "
                         "basis='standard')")
