"""Issue 23: residual interference of a sphere, the package's readings against the literature fits.

Prints, for a sphere (e1 = 1) at w* = omega_max/omega_c in (1, 2, 5, 10, 50, 110), the ratio
omega_res/omega_max of
  * the default "consistent" reading (recovered_interference, residual="consistent"), for two
    materials: the paper's convention (H given, K_Y Y = (2/pi) H) and a material with Y given
    (H = Y/0.354, K_Y = 1.282 + 1.158 nu);
  * the same number from the Hertz unloading matched to the loaded force and contact radius,
    omega_res = omega_max - 3 P_m/(4 E* a_m) (the unloading a public rough-contact code labels
    "Etsion et al., from Jackson 2010"), computed here from summit_loading's P_m and A_m;
  * the provisional residual="ekk" fit (ekk_residual_ratio: recalled, NOT verified);
  * the Jackson-Chusoipin-Green (2005) fit (jcg_residual_ratio, read from a public code).
Each column uses its own omega_c; the last two columns evaluate the JCG fit at the same
omega_max as the package (w*_JG = w* omega_c/omega_c,JG), and the last lines print
omega_c of the package (eq. (65)) over Jackson-Green's (C = 1.295 exp(0.736 nu), same Y;
Y = 0.354 H, Tabor, for the material given by H only).

Usage: PYTHONPATH=. .venv/bin/python benchmarks/bench_ekk.py [--nu 0.3]
"""
import argparse
import math

import numpy as np

from rough_contact.micro import unloading as U
from rough_contact.micro.asperity import AsperityMaterial

KAPPA = 20.0        # 1/mm; the ratios below do not depend on it
W_STARS = (1.0, 2.0, 5.0, 10.0, 50.0, 110.0)


def consistent_ratio(mat, ws):
    wc = float(U.summit_loading(0.0, KAPPA, 1.0, mat)["omega_c"])
    wm = np.asarray(ws) * wc
    w_res, _ = U.recovered_interference(wm, KAPPA, 1.0, mat)
    L = U.summit_loading(wm, KAPPA, 1.0, mat)
    a_m = np.sqrt(L["area"] / math.pi)
    hertz_matched = 1.0 - np.minimum(3.0 * L["load"] / (4.0 * mat.E_star * a_m * wm), 1.0)
    return w_res / wm, hertz_matched, wc


def jg_ratio(mat, wc, nu):
    """omega_c of the package over Jackson-Green's, same Y (Tabor Y = 0.354 H if Y is None)."""
    C = 1.295 * math.exp(0.736 * nu)
    Y = mat.Y if mat.Y is not None else 0.354 * mat.H
    return wc / ((math.pi * C * Y / (2.0 * mat.E_star)) ** 2 / KAPPA), Y


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--nu", type=float, default=0.3)
    a = ap.parse_args()
    nu = a.nu
    paper = AsperityMaterial(E_star=1.14e5, nu=nu, H=2000.0)
    with_y = AsperityMaterial(E_star=1.14e5, nu=nu, Y=0.354 * 2000.0)
    ws = np.array(W_STARS)
    r_p, hm_p, wc_p = consistent_ratio(paper, ws)
    r_y, hm_y, wc_y = consistent_ratio(with_y, ws)
    ekk = U.ekk_residual_ratio(ws)
    jcg = U.jcg_residual_ratio(ws)
    q_p, Y_p = jg_ratio(paper, wc_p, nu)
    q_y, Y_y = jg_ratio(with_y, wc_y, nu)
    jcg_p = U.jcg_residual_ratio(ws * q_p)       # JCG at the same omega_max (its own omega_c)
    jcg_y = U.jcg_residual_ratio(ws * q_y)
    print(f"sphere, nu = {nu}: omega_res/omega_max at w* = omega_max/omega_c (each its own "
          "omega_c)")
    print(f"{'w*':>6s} {'consistent':>11s} {'Hertz(P,a)':>11s} {'consistent':>11s} "
          f"{'Hertz(P,a)':>11s} {'ekk option':>11s} {'JCG 2005':>9s} {'JCG same':>9s} "
          f"{'JCG same':>9s}")
    print(f"{'':>6s} {'paper H':>11s} {'paper H':>11s} {'Y given':>11s} {'Y given':>11s} "
          f"{'(unverif.)':>11s} {'at w*':>9s} {'w_max, H':>9s} {'w_max, Y':>9s}")
    for i, w in enumerate(ws):
        print(f"{w:6.0f} {r_p[i]:11.4f} {hm_p[i]:11.4f} {r_y[i]:11.4f} {hm_y[i]:11.4f} "
              f"{ekk[i]:11.4f} {jcg[i]:9.4f} {jcg_p[i]:9.4f} {jcg_y[i]:9.4f}")
    for name, q, Y in (("paper H", q_p, Y_p), ("Y given", q_y, Y_y)):
        print(f"omega_c(package)/omega_c(Jackson-Green) [{name}, Y = {Y:.0f} MPa]: {q:.3f}")


if __name__ == "__main__":
    main()
