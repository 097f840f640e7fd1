"""Benchmark: the nonlinear rig's speed (issue 3).

Goals: one load case, response control included, under 10 s; the whole default rig
data set (`snakemake rig` from clean) under 40 s. Baseline in the same process: a plain
scipy.integrate.solve_ivp (RK45) integration of the same reduced model and contact laws
(the friction law as an ODE, dS/dt = dS/dxi * dxi/dt) over the same simulated time as the
numba integrator; the ratio is printed.

Usage: .venv/bin/python benchmarks/rig_dual_sine.py
"""

import sys
import time
from pathlib import Path

import numpy as np
import yaml
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))

from contactid.friction import valanis_slope  # noqa: E402
from contactid.rig.dual_sine import build_simulator, dual_sine_settings, dual_sine_test  # noqa: E402

sys.path.insert(0, str(ROOT / "benchmarks"))
from common import timed_clean_run  # noqa: E402


def solve_ivp_baseline(sim, F1, F3, w, t_end):
    """The same equations of motion, integrated by solve_ivp with a Python right-hand side."""
    r, c = sim.red, sim.contact
    e_f, k_c, e_t, kappa, mu = c.friction
    cdamp = 2 * sim.zeta * r.omega
    n = r.omega.size

    def rhs(t, y):
        z, v, S = y[:n], y[n : 2 * n], y[2 * n]
        gz = r.shortening @ z
        xi_lin = r.xi @ z
        xi = xi_lin - 0.5 * z @ gz
        dxi_dq = r.xi - gz
        dxi = dxi_dq @ v
        eta = r.eta @ z
        N = c.preload * max((c.static_approach - eta) / c.static_approach, 0.0) ** c.exponent
        dS = valanis_slope(S, xi, 1.0 if dxi >= 0 else -1.0, N, e_f, k_c, e_t, kappa, mu) * dxi if N > 0 else 0.0
        f = F1 * np.sin(w * t) + F3 * np.sin(3 * w * t)
        a = (
            r.force * f
            - dxi_dq * S
            + r.eta * (N - c.preload)
            + r.k_t * r.xi * xi_lin
            + r.k_n * r.eta * eta
            - cdamp * v
            - r.omega**2 * z
        )
        return np.concatenate([v, a, [dS]])

    y0 = np.concatenate([sim.z, sim.v, [sim.state[0]]])
    return solve_ivp(rhs, (0.0, t_end), y0, method="RK45", rtol=1e-6, atol=1e-12)


def main():
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    st, rig, lc1 = cfg["structure"], cfg["rig"], cfg["load_cases"]["lc1"]
    fs = cfg["random_test"]["sampling_rate_hz"]
    t0 = time.perf_counter()
    dual_sine_test(st, rig, lc1, fs, 0.005, 1, "lc1", st["sensors"]["names"])
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    raw, truth = dual_sine_test(st, rig, lc1, fs, 0.005, 1, "lc1", st["sensors"]["names"])
    warm = time.perf_counter() - t0
    print(
        f"one load case (lc1), response control included: {warm:.2f} s warm, {cold:.2f} s with JIT compilation "
        f"(goal < 10 s); control iterations {truth.sizes['iteration']}"
    )

    s = dual_sine_settings(rig, lc1, fs)
    sim = build_simulator(st, rig, s)
    w = 2 * np.pi * s["excitation_frequency_hz"]
    F1, F3 = truth.attrs["F1_n"], truth.attrs["F3_n"]
    sim.start_from_linear(F1, F3, w)
    t_end = 8 * 2 * np.pi / w
    n = int(round(t_end / sim.dt))
    sim.run(F1, F3, w, 100, store_from=None)  # compile
    sim.start_from_linear(F1, F3, w)
    t0 = time.perf_counter()
    sim.run(F1, F3, w, n, store_from=None)
    t_numba = time.perf_counter() - t0
    sim.start_from_linear(F1, F3, w)
    t0 = time.perf_counter()
    sol = solve_ivp_baseline(sim, F1, F3, w, t_end)
    t_ivp = time.perf_counter() - t0
    print(
        f"8 periods of lc1: numba central differences {t_numba * 1e3:.1f} ms, solve_ivp RK45 {t_ivp:.2f} s "
        f"({sol.t.size} steps); speed-up {t_ivp / t_numba:.0f}x"
    )

    wall = timed_clean_run("rig")
    print(f"whole default rig data set (snakemake rig, from clean, 2 cores): {wall:.1f} s (goal < 40 s)")


if __name__ == "__main__":
    main()
