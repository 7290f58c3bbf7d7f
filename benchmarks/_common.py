"""What the benchmark scripts share (imported as ``_common``: Python puts a script's own folder
first on ``sys.path``)."""

from __future__ import annotations

import csv
import functools
import os


def write_csv(path, rows) -> None:
    """Write ``rows`` (dicts with the keys of the first) to the CSV file ``path``, creating its
    folder."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


MEMORY_MATERIALS = ("paper", "psi", "psi=<value>")


def punch_material(material="paper"):
    """Asperity data of the punch's surface: ``"paper"`` the data of Figs 18-19
    (``flat_punch.PLASTIC``: Y = 2070 MPa, K_Y = 1.62, psi = 0.35); ``"psi"`` the same plasticity
    index psi = 0.35 (so the same hardness H) with the paper's default yield convention
    K_Y Y = (2/pi) H (Y not given); ``"psi=<value>"`` that convention at another plasticity
    index (H from psi and the surface)."""
    from rough_contact.micro.asperity import AsperityMaterial
    from rough_contact.scenes import flat_punch as P

    E_star = P.effective_modulus(P.E, P.NU, P.E, P.NU)
    if material == "paper":
        return AsperityMaterial(E_star=E_star, nu=P.NU, **P.PLASTIC)
    if material == "psi" or material.startswith("psi="):
        data = {k: v for k, v in P.PLASTIC.items() if k not in ("Y", "K_Y")}
        if material != "psi":
            data["psi"] = float(material[4:])
        return AsperityMaterial(E_star=E_star, nu=P.NU, **data)
    raise ValueError(f"material = {material!r} is invalid: valid values {MEMORY_MATERIALS}")


def punch_memory_law(cache_dir, rtol=1e-3, comm=None, material="paper"):
    """The flat punch's elasto-plastic population with memory (``HistoryNormalLaw.elasto_plastic``
    of the paper's section 9.2 surface and the asperity data ``material`` of
    :func:`punch_material`, strict=False), built once and cached as a pickle in ``cache_dir``
    (keyed by rtol, the surface moments and the asperity data; a cache of other data is
    rebuilt). Built on rank 0 and sent to the others (collective when ``comm`` is given).
    Returns ``(law, seconds, cached)``: the build's wall time (that of the cached build when
    read back) and whether it was read."""
    import pickle
    import time

    from rough_contact.scenes import flat_punch as P

    mat = punch_material(material)
    key = dict(rtol=rtol, moments=P.MOMENTS_UM, material=repr(mat), E=P.E, nu=P.NU)
    path = os.path.join(cache_dir, f"memory_law_{material}_rtol{rtol:g}.pkl")
    out = None
    if comm is None or comm.rank == 0:
        if os.path.exists(path):
            with open(path, "rb") as f:
                saved = pickle.load(f)
            if saved.get("key") == key:
                out = (saved["law"], saved["seconds"], True)
        if out is None:
            from rough_contact.interface.history import HistoryNormalLaw
            from rough_contact.surface import SpectralMoments

            surface = SpectralMoments(**P.MOMENTS_UM, unit="um")
            t0 = time.perf_counter()
            law = HistoryNormalLaw.elasto_plastic(surface, mat, rtol=rtol, strict=False)
            seconds = time.perf_counter() - t0
            os.makedirs(cache_dir, exist_ok=True)
            with open(path + ".tmp", "wb") as f:
                pickle.dump(dict(key=key, law=law, seconds=seconds), f)
            os.replace(path + ".tmp", path)
            out = (law, seconds, False)
    if comm is not None:
        out = comm.bcast(out, root=0)
    return out


def edge_bands(points, i, a, edges):
    """Per band [lo, hi) of r / ``a`` of the points in contact at increment ``i`` of a
    ``rough_contact.scenes.mindlin.PointSnapshot``: (lo, hi, in-band mask) for the non-empty
    bands, and the radial (outwards on the block positive) and hoop shears (n,) [MPa]."""
    import numpy as np
    rad, sh = points.r, points.shear[i]
    e_r = points.x[:, :2] / np.maximum(rad, 1e-300)[:, None]
    t_r = np.sum(sh * e_r, axis=1)
    t_h = e_r[:, 0] * sh[:, 1] - e_r[:, 1] * sh[:, 0]
    on = points.contact[i]
    bands = [(lo, hi, on & (rad >= lo * a) & (rad < hi * a))
             for lo, hi in zip(edges[:-1], edges[1:])]
    return [b for b in bands if b[2].any()], t_r, t_h


PROFILE_EDGES = (0.0, 0.5, 0.7, 0.8, 0.9, 0.95, 0.97, 0.98, 0.99, 1.0, 1.01)
"""Bands of r / a_Hertz of :func:`normal_load_profile`."""


@functools.lru_cache(maxsize=8)
def spence_profile(beta_over_mu, edges=PROFILE_EDGES, rings=400):
    """The continuum's shear under the normal load alone (Spence's problem,
    ``rough_contact.frictional_hertz.slip_annulus``) per band [lo, hi) of r / a: (mean radial
    shear / mu p0, largest q / (mu p)) for each band inside the contact (nan beyond a)."""
    import numpy as np
    from rough_contact.frictional_hertz import slip_annulus
    s = slip_annulus(beta_over_mu, rings=rings)
    out = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        m = (s.r >= lo) & (s.r < min(hi, 1.0))
        if not m.any():
            out.append((float("nan"), float("nan")))
            continue
        out.append((float(s.shear[m].mean()), float((s.shear[m] / s.pressure[m]).max())))
    return out


def normal_load_profile(points, i, a, mu, beta_over_mu, edges=PROFILE_EDGES):
    """Lines of a table of the shear at increment ``i`` of a Mindlin run's gathered points
    (``rough_contact.scenes.mindlin.PointSnapshot``) per band of r / ``a`` (Hertz's radius):
    vertices in contact, slipping ones, the mean radial shear (outwards on the block positive)
    / mu p0 and the largest |t| / (mu p), against the continuum's (:func:`spence_profile`);
    p0: the largest pressure of the increment."""
    import numpy as np
    p = points.pressure[i]
    mu_p0 = mu * p.max()
    bands, t_r, _ = edge_bands(points, i, a, edges)
    ratio = np.linalg.norm(points.shear[i], axis=1) / np.maximum(mu * p, 1e-300)
    cont = dict(zip(zip(edges[:-1], edges[1:]), spence_profile(beta_over_mu, tuple(edges))))
    lines = [f"  {'r/a_H':>10} {'contact':>7} {'slip':>5} {'t_r/mu p0':>9} {'Spence':>7} "
             f"{'max|t|/mu p':>11} {'Spence':>7}"]
    for lo, hi, m in bands:
        c_mean, c_max = cont[(lo, hi)]
        lines.append(f"  {lo:4.2f}-{hi:4.2f} {int(m.sum()):7d} "
                     f"{int((points.slipping[i] & m).sum()):5d} {t_r[m].mean() / mu_p0:+9.4f} "
                     f"{c_mean:+7.4f} {ratio[m].max():11.3f} {c_max:7.3f}")
    return lines
