"""Benchmark: the gap diagnosis of one data set (three load cases), issue 7.

Goal: the whole diagnosis (baseline simulations, localisation, eight candidates refitted on the
calibration case and predicted on the held-out cases, bootstrap) under 2 minutes on this machine.
Also the speed-up of the simulation's harmonic extraction (FFT of the period mean on a step
that divides the period) over the plain least-squares fit of sines and cosines, in this process.

Needs the default workflow's results (`.venv/bin/snakemake -c2` or `snakemake gap` first).
Usage: .venv/bin/python benchmarks/gap_diagnosis.py
"""

import sys
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))

from contactid.friction_fit import settings_from_config  # noqa: E402
from contactid.gap.diagnosis import GapSettings, diagnose, linear_stage  # noqa: E402
from contactid.gap.model import NONE, identified_model, periodic_harmonics, simulator  # noqa: E402
from contactid.gap.records import record_harmonics  # noqa: E402
from contactid.io import load_dataset, read_raw  # noqa: E402
from contactid.signals import harmonic_amplitudes  # noqa: E402


def main():
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    res = ROOT / "results"
    model = identified_model(cfg["structure"], load_dataset(res / "linear/linear_modes.nc"),
                             load_dataset(res / "linear/modal.nc"), load_dataset(res / "friction/friction_fit.nc"))
    K = cfg["nonlinear"]["n_harmonics"]
    records = {c: record_harmonics(read_raw(ROOT / "data/raw" / f"{c}.nc", dual_sine=True), c, K) for c in ("lc1", "lc2", "lc3")}
    # harmonic extraction: FFT of the period mean against least squares, on the same simulated record
    rec = records["lc1"]
    sim = simulator(model, NONE, rec.fs, rec.f0)
    w = 2 * np.pi * rec.f0
    sim.start_from_linear(rec.force[:5], None, w)
    n_per = int(round(2 * np.pi / w / sim.dt))
    out = sim.run(rec.force[:5], None, w, 16 * n_per, store_from=0)
    acc = (out["a"] @ sim.red.sensors.T).T
    t0 = time.perf_counter()
    for _ in range(20):
        fast = periodic_harmonics(acc, out["t"][0], w, n_per, 9)
    t_fast = (time.perf_counter() - t0) / 20
    t0 = time.perf_counter()
    plain = np.array([harmonic_amplitudes(a, out["t"], w, range(1, 10)) for a in acc])
    t_plain = time.perf_counter() - t0
    print(f"harmonics of a 16-period simulation: FFT {1e3 * t_fast:.2f} ms, least squares {1e3 * t_plain:.1f} ms "
          f"(x{t_plain / t_fast:.0f}); max difference {np.max(np.abs(fast - plain)) / np.max(np.abs(plain)):.1e} (relative)")
    settings = GapSettings.from_config(cfg["gap"], cfg["seed"], K)
    t0 = time.perf_counter()
    d = diagnose(model, records, "lc1", settings, settings_from_config(cfg["friction"]),
                 linear_stage(model, load_dataset(res / "linear/frf.nc"), load_dataset(res / "linear/modal.nc")))
    wall = time.perf_counter() - t0
    print(f"diagnosis of 3 load cases, {len(d.ranking)} candidates: {wall:.1f} s (goal 120 s: "
          f"{'met' if wall < 120 else 'NOT met'}); verdict {d.verdict}")


if __name__ == "__main__":
    main()
