"""Benchmark: the gap diagnosis of one data set (three load cases), issue 14.

Goal: the whole diagnosis (baseline simulations, localisation, eight candidates refitted on the
calibration case and predicted on the held-out cases, bootstrap) in at most 15 s on this machine,
at least 5 x faster than the diagnosis as it was before harmonic balance (the package at commit
REFERENCE, every steady state by time marching until the harmonics settle; extracted with
`git archive` and imported as `contactid_ref`), run in the same process on the same identified
model and records. Both must give the same verdict and ranking order; the held-out gaps are
printed side by side (harmonic balance solves the integrator's discrete equations; what differs is
the harmonics it leaves out, about 1e-4 of the response). Also printed: the new package forced
to time marching without memoisation (what harmonic balance and the memos alone buy), and the new
package with its candidates in two worker processes (as the gap_diagnosis rule runs them).

Data sets: the default workflow's records (effect-free), and three rig data sets with one effect
each (generated, identified and cached under benchmarks/cache/ on the first run, about a minute
each).

Needs the default workflow's results (`.venv/bin/snakemake -c2` first).
Usage: .venv/bin/python benchmarks/gap_diagnosis.py [--only default]
"""

import importlib
import io
import json
import os
import subprocess
import sys
import tarfile
import time
from pathlib import Path

# one BLAS thread, as the gap_diagnosis rule runs (threads: 1); both diagnoses run under it
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))

from contactid.friction_parameters import parameter_dataset  # noqa: E402
from contactid.gap.model import STEADY_STATE  # noqa: E402
from contactid.gap.refit import memoised  # noqa: E402
from contactid.io import load_dataset, read_raw  # noqa: E402

CACHE = ROOT / "benchmarks" / "cache"
REFERENCE = "e0eaa32"  # the last commit before harmonic balance


def reference_package():
    """The package as it was at REFERENCE, importable as contactid_ref (its imports are relative)."""
    dest = CACHE / f"reference-{REFERENCE}"
    if not (dest / "contactid_ref").exists():
        tar = subprocess.run(
            ["git", "archive", REFERENCE, "workflow/contactid"], cwd=ROOT, capture_output=True, check=True
        ).stdout
        with tarfile.open(fileobj=io.BytesIO(tar)) as t:
            t.extractall(dest, filter="data")
        (dest / "workflow" / "contactid").rename(dest / "contactid_ref")
    sys.path.insert(0, str(dest))
    return importlib.import_module("contactid_ref")


EFFECTS = {"normal_contact_damping": 300.0, "viscous_friction": 300.0, "transducer_mass_error": 0.3}


def default_data(cfg):
    res = ROOT / "results"
    ds = {k: load_dataset(res / f"linear/{k}.nc") for k in ("linear_modes", "modal", "frf")}
    ds["friction_fit"] = load_dataset(res / "friction/friction_fit.nc")
    raw = {c: read_raw(ROOT / "data/raw" / f"{c}.nc", dual_sine=True) for c in sorted(cfg["load_cases"])}
    return ds, raw


def effect_data(cfg, effect, magnitude):
    """Rig records with one effect (cached as netCDF), identified as the workflow does."""

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
    fit = parameter_dataset(model.friction, model.regularization)
    return {"linear_modes": modes, "modal": modal, "frf": frf, "friction_fit": fit}, {c: recs[c] for c in cases}


def run(pkg, method, memo, ds, raw, cfg, warm_up=False, workers=1):
    """One diagnosis with package ``pkg`` (contactid or contactid_ref) on the datasets and raw records."""
    gm = importlib.import_module(f"{pkg}.gap.model")
    gd = importlib.import_module(f"{pkg}.gap.diagnosis")
    model = gm.identified_model(cfg["structure"], ds["linear_modes"], ds["modal"], ds["friction_fit"])
    K = cfg["nonlinear"]["n_harmonics"]
    records = {c: importlib.import_module(f"{pkg}.gap.records").record_harmonics(r, c, K) for c, r in raw.items()}
    lin = gd.linear_stage(model, ds["frf"], ds["modal"])
    gap = (
        {**cfg["gap"], "candidates": ["multi_asperity_friction", "preload_drift"], "max_evaluations": 3}
        if warm_up
        else cfg["gap"]
    )
    settings = gd.GapSettings.from_config(gap, cfg["seed"], K)
    fit_settings = importlib.import_module(f"{pkg}.friction_fit").settings_from_config(cfg["friction"])
    token = STEADY_STATE.set(method) if pkg == "contactid" else None
    try:
        with memoised(memo if pkg == "contactid" else True):
            t0 = time.perf_counter()
            kw = {"workers": workers} if workers > 1 else {}
            d = gd.diagnose(model, records, cfg["nonlinear"]["calibration_case"], settings, fit_settings, lin, **kw)
            return d, time.perf_counter() - t0
    finally:
        if token is not None:
            STEADY_STATE.reset(token)


def compare(label, ds, raw, cfg) -> dict:
    run("contactid", "harmonic_balance", True, ds, raw, cfg, warm_up=True)  # compile or load every kernel once
    run("contactid_ref", None, None, ds, raw, cfg, warm_up=True)
    new, t_new = run("contactid", "harmonic_balance", True, ds, raw, cfg)
    old, t_old = run("contactid_ref", None, None, ds, raw, cfg)
    _, t_plain = run("contactid", "time_marching", False, ds, raw, cfg)
    two, t_two = run("contactid", "harmonic_balance", True, ds, raw, cfg, workers=2)
    order_old = [r["effect"] for r in old.ranking]
    order_new = [r["effect"] for r in new.ranking]
    before = (old.where["heldout_gap_before"], new.where["heldout_gap_before"])
    after = {r["effect"]: r["heldout_gap_after"] for r in old.ranking}
    diffs = [abs(r["heldout_gap_after"] - after[r["effect"]]) for r in new.ranking]
    rel = [abs(r["heldout_gap_after"] / after[r["effect"]] - 1) for r in new.ranking]
    row = {
        "data": label,
        "seconds_reference": t_old,
        "seconds_harmonic_balance": t_new,
        "seconds_time_marching_unmemoised": t_plain,
        "seconds_two_workers": t_two,
        "same_with_two_workers": [r["effect"] for r in two.ranking] == [r["effect"] for r in new.ranking],
        "ratio": t_old / t_new,
        "verdict": [old.verdict, new.verdict],
        "same_verdict": old.verdict == new.verdict,
        "same_ranking": order_old == order_new,
        "ranking": [order_old, order_new],
        "heldout_gap_before": list(before),
        "heldout_gap_after": [[after[e] for e in order_old], [r["heldout_gap_after"] for r in new.ranking]],
        "max_abs_gap_difference": max([abs(before[1] - before[0]), *diffs]),
        "max_rel_gap_difference": max([abs(before[1] / before[0] - 1), *rel]),
    }
    print(
        f"{label}: before harmonic balance ({REFERENCE}) {t_old:.1f} s, now {t_new:.1f} s (x{row['ratio']:.1f}; now "
        f"forced to time marching without memos {t_plain:.1f} s; with two worker processes {t_two:.1f} s, "
        f"{'same' if row['same_with_two_workers'] else 'OTHER'} ranking); "
        f"verdict {old.verdict} / {new.verdict}; ranking "
        f"{'same' if row['same_ranking'] else 'DIFFERENT'}; held-out gap before {before[0]:.4%} / {before[1]:.4%}; "
        f"largest held-out gap difference {row['max_abs_gap_difference']:.2e} (absolute), "
        f"{row['max_rel_gap_difference']:.1%} (relative)",
        flush=True,
    )
    if not row["same_ranking"]:
        print("  before:", order_old, "\n  now:   ", order_new)
    return row


def main():
    from contactid.gap.diagnosis import _pool

    _pool(2)  # forked now, before numba's parallel threads start in this process (the runs with two workers)
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    reference_package()
    only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else None
    rows = []
    if only in (None, "default"):
        rows.append(compare("default (effect-free)", *default_data(cfg), cfg))
    for effect, magnitude in EFFECTS.items():
        if only in (None, effect):
            rows.append(compare(f"{effect} {magnitude:g}", *effect_data(cfg, effect, magnitude), cfg))
    worst = max(r["seconds_harmonic_balance"] for r in rows)
    print(
        f"slowest diagnosis {worst:.1f} s (goal 15 s: {'met' if worst <= 15 else 'NOT met'}); smallest ratio "
        f"x{min(r['ratio'] for r in rows):.1f} (goal 5: {'met' if min(r['ratio'] for r in rows) >= 5 else 'NOT met'})"
    )
    CACHE.mkdir(parents=True, exist_ok=True)
    (CACHE / "gap_diagnosis.json").write_text(json.dumps(rows, indent=2, default=str))


if __name__ == "__main__":
    main()
