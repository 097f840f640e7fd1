"""Benchmark: the gap diagnosis of one data set (three load cases), issue 14.

Goal: the whole diagnosis (baseline simulations, localisation, eight candidates refitted on the
calibration case and predicted on the held-out cases, bootstrap) in at most 15 s on this machine,
at least 5 x faster than the plain baseline run in the same process: every steady state by time
marching until the harmonics settle, nothing memoised (the diagnosis as it was before harmonic
balance). Both must give the same verdict and ranking order and the same held-out gaps.

Data sets: the default workflow's records (effect-free), and three rig data sets with one effect
each (generated, identified and cached under benchmarks/cache/ on the first run, about a minute
each).

Needs the default workflow's results (`.venv/bin/snakemake -c2` first).
Usage: .venv/bin/python benchmarks/gap_diagnosis.py [--only default]
"""

import json
import sys
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))

from contactid.friction_fit import settings_from_config  # noqa: E402
from contactid.gap.diagnosis import GapSettings, diagnose, linear_stage  # noqa: E402
from contactid.gap.model import STEADY_STATE, identified_model  # noqa: E402
from contactid.gap.records import record_harmonics  # noqa: E402
from contactid.gap.refit import memoised  # noqa: E402
from contactid.io import load_dataset, read_raw  # noqa: E402

CACHE = ROOT / "benchmarks" / "cache"
EFFECTS = {"normal_contact_damping": 300.0, "viscous_friction": 300.0, "transducer_mass_error": 0.3}


def default_data(cfg):
    res = ROOT / "results"
    model = identified_model(cfg["structure"], load_dataset(res / "linear/linear_modes.nc"),
                             load_dataset(res / "linear/modal.nc"), load_dataset(res / "friction/friction_fit.nc"))
    K = cfg["nonlinear"]["n_harmonics"]
    records = {c: record_harmonics(read_raw(ROOT / "data/raw" / f"{c}.nc", dual_sine=True), c, K)
               for c in sorted(cfg["load_cases"])}
    lin = linear_stage(model, load_dataset(res / "linear/frf.nc"), load_dataset(res / "linear/modal.nc"))
    return model, records, lin


def effect_data(cfg, effect, magnitude):
    """Rig records with one effect, identified as the workflow does (cached as netCDF)."""
    from contactid.gap.pipeline import identify, rig_records

    folder = CACHE / f"{effect}-{magnitude:g}"
    cases = sorted(cfg["load_cases"])
    names = ["random_test", *cases]
    if not all((folder / f"{n}.nc").exists() for n in names):
        folder.mkdir(parents=True, exist_ok=True)
        recs, _ = rig_records(cfg, {effect: magnitude}, 1, cases)
        for n in names:
            recs[n].to_netcdf(folder / f"{n}.nc", engine="netcdf4")
    recs = {n: load_dataset(folder / f"{n}.nc") for n in names}
    model, modes, modal, frf = identify(cfg, recs["random_test"], recs[cfg["nonlinear"]["calibration_case"]])
    K = cfg["nonlinear"]["n_harmonics"]
    records = {c: record_harmonics(recs[c], c, K) for c in cases}
    return model, records, linear_stage(model, frf, modal)


def run(method, memo, model, records, lin, cfg):
    settings = GapSettings.from_config(cfg["gap"], cfg["seed"], cfg["nonlinear"]["n_harmonics"])
    token = STEADY_STATE.set(method)
    try:
        with memoised(memo):
            t0 = time.perf_counter()
            d = diagnose(model, records, cfg["nonlinear"]["calibration_case"], settings,
                         settings_from_config(cfg["friction"]), lin)
            return d, time.perf_counter() - t0
    finally:
        STEADY_STATE.reset(token)


def compare(label, model, records, lin, cfg) -> dict:
    run("harmonic_balance", True, model, records, lin, cfg)  # compile and warm every kernel once
    new, t_new = run("harmonic_balance", True, model, records, lin, cfg)
    old, t_old = run("time_marching", False, model, records, lin, cfg)
    order_old = [r["effect"] for r in old.ranking]
    order_new = [r["effect"] for r in new.ranking]
    before = (old.where["heldout_gap_before"], new.where["heldout_gap_before"])
    after = {r["effect"]: r["heldout_gap_after"] for r in old.ranking}
    diffs = [abs(r["heldout_gap_after"] - after[r["effect"]]) for r in new.ranking]
    rel = [abs(r["heldout_gap_after"] / after[r["effect"]] - 1) for r in new.ranking]
    row = {"data": label, "seconds_time_marching": t_old, "seconds_harmonic_balance": t_new, "ratio": t_old / t_new,
           "verdict": [old.verdict, new.verdict], "same_verdict": old.verdict == new.verdict,
           "same_ranking": order_old == order_new, "heldout_gap_before": list(before),
           "max_abs_gap_difference": max([abs(before[1] - before[0]), *diffs]),
           "max_rel_gap_difference": max([abs(before[1] / before[0] - 1), *rel])}
    print(f"{label}: time marching {t_old:.1f} s, harmonic balance {t_new:.1f} s (x{row['ratio']:.1f}); verdict "
          f"{old.verdict} / {new.verdict}; ranking {'same' if row['same_ranking'] else 'DIFFERENT'}; held-out gap "
          f"before {before[0]:.4%} / {before[1]:.4%}; largest gap difference {row['max_abs_gap_difference']:.2e} "
          f"(absolute), {row['max_rel_gap_difference']:.1%} (relative)", flush=True)
    if not row["same_ranking"]:
        print("  time marching:   ", order_old, "\n  harmonic balance:", order_new)
    return row


def main():
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else None
    rows = []
    if only in (None, "default"):
        rows.append(compare("default (effect-free)", *default_data(cfg), cfg))
    for effect, magnitude in EFFECTS.items():
        if only in (None, effect):
            rows.append(compare(f"{effect} {magnitude:g}", *effect_data(cfg, effect, magnitude), cfg))
    worst = max(r["seconds_harmonic_balance"] for r in rows)
    print(f"slowest diagnosis {worst:.1f} s (goal 15 s: {'met' if worst <= 15 else 'NOT met'}); smallest ratio "
          f"x{min(r['ratio'] for r in rows):.1f} (goal 5: {'met' if min(r['ratio'] for r in rows) >= 5 else 'NOT met'})")
    CACHE.mkdir(parents=True, exist_ok=True)
    (CACHE / "gap_diagnosis.json").write_text(json.dumps(rows, indent=2, default=str))


if __name__ == "__main__":
    main()
