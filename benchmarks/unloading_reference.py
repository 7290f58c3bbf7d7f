"""Independent reference of the unloading population sums (issue 23).

p(h, h_min), k = -dp/dh|_{h_min} and A/A0 as a nested adaptive scipy ``quad`` over the paper's
own summit variables (w1, w4, w6) with the joint density (18) (``psum``'s formula, written out
here), and the single-summit unloading law written again in scalar Python: no code of
``rough_contact.micro.unloading`` (its (K, zeta) coordinates, windows, panels, Gauss rules) is
used; only the shape factors f1, f2, f3, K E of ``asperity.py`` at each (w4, w6).
Slow: several minutes per point at epsrel 1e-7 (pure Python integrand).

Usage: PYTHONPATH=. python benchmarks/unloading_reference.py S_MIN X [EPSREL]
       (h_min = S_MIN sigma, h = h_min + X sigma, Table 1 surface, psi = 1)
"""
import math, time
import numpy as np
from scipy import integrate, optimize
from rough_contact.micro.asperity import shape_factors_from_lambda

def reference(surface, mat, h, h_min, epsrel=1e-9, wmax=10.0):
    b1, b2, mu = surface.beta1, surface.beta2, surface.mu
    sb1, sb2 = math.sqrt(b1), math.sqrt(b2)
    smu = math.sqrt(surface.m00 * mu)
    s40, s04 = math.sqrt(surface.m40 * mu), math.sqrt(surface.m04 * mu)
    Es, H, ch, R, Kn = mat.E_star, mat.H, mat.ch, mat.omega_p_ratio, mat.K_nu
    pY = mat.yield_pressure
    slope = H * (ch - 2.0 * Kn / 3.0) / math.log(R)
    l, u = h_min / smu, h - h_min
    c0 = mu * mu / math.sqrt(2 * math.pi)

    def inner(w4, w6, comp):
        kx, ky = w4 * s40, w6 * s04
        kap = 0.5 * (kx + ky)
        lam = math.sqrt(min(kx, ky) / max(kx, ky))
        f1, f2, f3, KE = (float(v) for v in shape_factors_from_lambda(np.array(lam)))
        wc = KE * (pY / Es) ** 2 / kap
        wp = R * wc

        def load(W):
            if W < wc:
                return f1 * math.pi * W / kap, 4.0 / 3.0 * Es * f2 / math.sqrt(kap) * W ** 1.5
            if W < wp:
                x = (W - wc) / (wp - wc)
                A = math.pi * W / kap * (f1 + (2 * f3 - f1) * x * x * (3 - 2 * x))
                return A, A * (ch * H - slope * math.log(wp / W))
            A = 2 * f3 * math.pi * W / kap
            return A, ch * H * A

        def de(W):
            if W < wc:
                return W
            A, P = load(W)
            return min(W, 1.5 * P / (2 * Es * f2 / math.sqrt(f1) * math.sqrt(A / math.pi)))

        mean = sb1 * w4 + sb2 * w6
        g0 = math.exp(-0.5 * mu * (w4 * w4 + w6 * w6)) * w4 * w6 * c0

        def f(w1):
            W = smu * (w1 - l)
            d = de(W)
            if d <= u:
                return 0.0
            A, P = load(W)
            xi = 1.0 - u / d
            q = (P * xi ** 1.5, 1.5 * P * math.sqrt(xi) / d, A * xi)[comp]
            return q * g0 * math.exp(-0.5 * (w1 - mean) ** 2)

        top = max(l, mean) + 13.0
        ivs = []
        if u < wc:
            ivs.append((l + u / smu, l + wc / smu))
        wc1 = wc * (1 + 1e-13)
        if de(wc1) >= u:
            start = wc
        elif de(wp) <= u:
            # plastic: delta_e = C sqrt(W)
            start = optimize.brentq(lambda W: de(W) - u, wp, wp * 1e8, xtol=1e-16 * wp, rtol=1e-15)
        else:
            start = optimize.brentq(lambda W: de(W) - u, wc1, wp, xtol=1e-16 * wc, rtol=1e-15)
        ivs.append((l + start / smu, top))
        tot = 0.0
        for a, b in ivs:
            if b <= a:
                continue
            pts = [x for x in (l + wp / smu, mean) if a < x < b]
            tot += integrate.quad(f, a, b, points=pts or None, epsabs=0, epsrel=epsrel,
                                  limit=200)[0]
        return tot

    out = []
    for comp in range(3):
        mid = lambda w4: integrate.quad(lambda w6: inner(w4, w6, comp), 0, wmax, epsabs=0,
                                        epsrel=epsrel * 10, limit=200)[0]
        out.append(integrate.quad(mid, 0, wmax, epsabs=0, epsrel=epsrel * 10, limit=200)[0])
    return np.array(out) * surface.summit_density

if __name__ == "__main__":
    import sys
    from rough_contact.micro.asperity import AsperityMaterial
    from rough_contact.surface import SpectralMoments
    S1 = SpectralMoments(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)
    mat = AsperityMaterial(E_star=1.14e5, psi=1.0).resolve(S1)
    sig = S1.rq
    hm, x = float(sys.argv[1]) * sig, float(sys.argv[2])
    t = time.time()
    r = reference(S1, mat, hm + x * sig, hm, epsrel=float(sys.argv[3]) if len(sys.argv) > 3 else 1e-9)
    print(r, time.time() - t)
