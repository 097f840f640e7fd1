"""Benchmark: the friction kernel and the whole fit (issue 5).

Goals: the fast kernel at most 40 ns per sample per parameter set (per integration step),
its speed-up over the plain per-sample Python loop printed; the whole fit (GA + polish +
refinement + intervals, default settings) under 10 s.

Usage: .venv/bin/python benchmarks/friction.py
"""

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))

from contactid.friction import valanis_friction_force, valanis_friction_force_reference  # noqa: E402
from contactid.friction_fit import FitSettings, fit_friction_law  # noqa: E402

TRUE = np.array([3.857e7, 2.547e5, 1.0e4, 0.284, 0.397])


def main():
    m = 256
    t = np.arange(m) / m
    xi = 1e-5 * np.sin(2 * np.pi * t) + 3e-6 * np.sin(6 * np.pi * t + 0.3)
    n = 70 + 12 * np.sin(2 * np.pi * t + 0.5)
    rng = np.random.default_rng(0)
    pop = TRUE * (0.8 + 0.4 * rng.random((256, 5)))
    valanis_friction_force(xi, n, pop[:2])  # compile
    _, periods = valanis_friction_force(xi, n, pop, return_periods=True)
    reps = 20
    t0 = time.perf_counter()
    for _ in range(reps):
        valanis_friction_force(xi, n, pop)
    fast = (time.perf_counter() - t0) / reps
    steps = m * periods.sum()
    t0 = time.perf_counter()
    valanis_friction_force_reference(xi, n, pop[:8])
    ref = (time.perf_counter() - t0) / 8 * pop.shape[0]
    print(
        f"fast kernel: {fast / steps * 1e9:.1f} ns per sample step per parameter set (goal <= 40), "
        f"{fast / (m * pop.shape[0]) * 1e9:.0f} ns per sample per set per call ({periods.mean():.1f} periods to "
        f"steady state); plain per-sample Python loop: {ref / steps * 1e9:.0f} ns; speed-up {ref / fast:.0f}x"
    )

    m2 = 2048
    t2 = np.arange(m2) / m2
    xi2 = 1e-5 * np.sin(2 * np.pi * t2) + 3e-6 * np.sin(6 * np.pi * t2 + 0.3)
    n2 = 70 + 12 * np.sin(2 * np.pi * t2 + 0.5)
    S = valanis_friction_force(xi2, n2, TRUE[None])[0]

    def coef(x):
        return (2j * np.fft.fft(x)[1:26] / x.size)[None]

    t0 = time.perf_counter()
    res = fit_friction_law(coef(xi2), coef(n2 - 70), coef(S), 54.375, 70.0, FitSettings(), 1, 25)
    print(
        f"whole fit (GA {FitSettings().population} x {FitSettings().generations}, polish, grid up to "
        f"{res.grid_points}, intervals): {time.perf_counter() - t0:.2f} s (goal < 10 s)"
    )


if __name__ == "__main__":
    main()
