"""A closed-form irreversible normal law shared by the tests (issue 23): the stand-in for the
tabulated elasto-plastic population with memory (``HistoryNormalLaw.elasto_plastic``, too slow
to build in a test), implementing the same ``HistoryNormalLawProtocol``.

Loading p_L(h) = C exp(-h/LAM); unloading from the smallest separation h_min along
p = p_L(h_min) (1 - (h - h_min)/DELTA)^(3/2), zero beyond h_min + DELTA (a Hertz-like elastic
recovery of fixed extent DELTA). Its dissipation has the closed form
D(h_min) = int_{h_min}^inf p_L - int_{h_min}^{h_min + DELTA} p_u = p_L(h_min) (LAM - 2 DELTA/5).
A/A0 = min(p / 100 MPa, 1). Units: mm, MPa, N/mm.

Imported by tests/unit/test_history_law.py and tests/fem (which put this folder on sys.path).
"""
from __future__ import annotations

import numpy as np

C, LAM, DELTA = 50.0, 1e-3, 1.5e-3      # MPa, mm, mm


class MemoryLaw:
    """p = C exp(-h/LAM) on loading; p = p_L(h_min) x^1.5, x = 1 - (h - h_min)/delta unloading
    (delta = DELTA unless a subclass sets another recovery extent)."""

    delta = DELTA

    def evaluate(self, h, curvature=False):
        h = np.asarray(h, float)
        p = C * np.exp(-h / LAM)
        out = (p, p / LAM, np.minimum(p / 100.0, 1.0))
        return out + (-p / LAM ** 2,) if curvature else out

    def separation_for_pressure(self, p):
        return -LAM * np.log(np.asarray(p, float) / C)

    def evaluate_history(self, h, h_min, curvature=False):
        h, hm = np.broadcast_arrays(np.asarray(h, float), np.asarray(h_min, float))
        lo = np.minimum(h, hm)
        p0 = C * np.exp(-lo / LAM)
        x = np.clip(1.0 - (h - lo) / self.delta, 0.0, 1.0)
        un = h > hm
        p = np.where(un, p0 * x ** 1.5, p0)
        k = np.where(un, 1.5 * p0 * np.sqrt(x) / self.delta, p0 / LAM)
        a = np.minimum(p / 100.0, 1.0)
        if curvature:
            dk = np.where(un, -0.75 * p0 / (self.delta ** 2 * np.sqrt(np.maximum(x, 1e-300))),
                          -p0 / LAM ** 2)
            return p, k, a, np.where(un & (x <= 0), 0.0, dk)
        return p, k, a

    def normal_dissipation(self, h_min):
        """D(h_min) = int_{h_min}^inf p_load - int_{h_min}^{h_min + DELTA} p_unload."""
        hm = np.asarray(h_min, float)
        return np.where(np.isfinite(hm), C * np.exp(-np.minimum(hm, 1e300) / LAM)
                        * (LAM - 0.4 * self.delta), 0.0)
