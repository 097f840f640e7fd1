"""Benchmark: the gap diagnosis of one data set (three load cases), issue 14.

Goal: the whole diagnosis (baseline simulations, localisation, eight candidates refitted on the
calibration case and predicted on the held-out cases, the explanation's later passes, bootstrap) in at
most 15 s on this machine, at least 5 x faster than the plain diagnosis run in the same process on the
same identified model and records: every steady state by time marching until the harmonics settle, no
memos, the calibration searches on the gap alone (Brent, Nelder-Mead) -- the diagnosis as issue 14
found it, on today's models and candidate library. Printed beside it:
- the same time-marching run with today's residual-vector searches: what the solver (harmonic balance
  and the memos) changes; verdict and ranking must be the same, held-out gaps within 0.1 %;
- the diagnosis with the other setting of ``gap.polish_searches`` (``Numerics.polish_searches``; the config's, true,
  polishes every searched state by the integrator, so that the searches stop where the time-marching ones stop; false
  compares the harmonic-balance states alone, faster, and stops elsewhere where the calibration gap is flat);
- the diagnosis with its candidates in two worker processes (as the gap_diagnosis rule runs them);
- with ``--reference-scatter``, the time-marching diagnosis itself at half and at double its settling tolerance
  (``Numerics.settling_tol``, 2e-5): how far the reference's own held-out gaps move within its tolerance, the
  scale the 0.1 % above is to be read against;
- with ``--tight-tolerance TOL``, the time-marching diagnosis and the one with every searched state polished, both
  at the settling tolerance TOL (5e-7, say): as the reference converges, the fast diagnosis's held-out gaps converge
  on its (docs/measurements.md);
- with ``--with-reference``, the package at REFERENCE (the last commit before harmonic balance, imported
  from git as ``contactid_ref``); its friction kernel is the old slip-limit one, so only its time and
  verdict are printed.

Data sets: the default workflow's records (effect-free), and three rig data sets with one effect
each (generated, identified and cached under benchmarks/cache/ on the first run, about a minute
each).

Needs the default workflow's results (`.venv/bin/snakemake -c2` first; `CONTACTID_RESULTS=DIR` reads another project's).
Usage: .venv/bin/python benchmarks/gap_diagnosis.py [--only default|EFFECT] [--with-reference] [--reference-scatter]
       [--tight-tolerance TOL]
"""

import dataclasses
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

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))

from contactid.friction_parameters import parameter_dataset  # noqa: E402
from contactid.gap.numerics import DEFAULT, Numerics  # noqa: E402
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
            # the "data" filter where this Python has it (3.11.4 and later); a git archive of our own tree otherwise
            kw = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
            t.extractall(dest, **kw)
        (dest / "workflow" / "contactid").rename(dest / "contactid_ref")
    sys.path.insert(0, str(dest))
    return importlib.import_module("contactid_ref")


EFFECTS = {"normal_contact_damping": 300.0, "viscous_friction": 300.0, "transducer_mass_error": 0.3}


def default_data(cfg):
    project = Path(os.environ.get("CONTACTID_RESULTS", ROOT))
    res = project / "results"
    ds = {k: load_dataset(res / f"linear/{k}.nc") for k in ("linear_modes", "modal", "frf")}
    ds["friction_fit"] = load_dataset(res / "friction/friction_fit.nc")
    raw = {c: read_raw(project / "data/raw" / f"{c}.nc", dual_sine=True) for c in sorted(cfg["load_cases"])}
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


def _reference_fit(fit):
    """The friction fit as REFERENCE reads it: one variable ``parameter_value`` over the parameters (today's dataset
    has a variable per parameter, ``contactid.friction_parameters``)."""
    import xarray as xr
    from contactid.friction_parameters import PARAMETER_NAMES, fitted_parameters

    return xr.Dataset(
        {"parameter_value": ("parameter", fitted_parameters(fit))}, coords={"parameter": list(PARAMETER_NAMES)}
    )


def run(
    pkg, method, memo, ds, raw, cfg, warm_up=False, workers=1, search="residual", polish_search=None, settle_tol=None
):
    """One diagnosis with package ``pkg`` (contactid or contactid_ref) on the datasets and raw records: steady states
    by ``method``, memos on or off, the calibration searches on the residual vector or the gap alone (``search``),
    every searched state polished by the integrator or not (``polish_search``; None: as the config's
    gap.polish_searches), the integrator's settling tolerance (``settle_tol``; None: ``Numerics``' default), all of
    them the diagnosis's ``GapSettings.numerics`` (``contactid.gap.numerics.Numerics``; contactid_ref has its own
    defaults)."""
    if polish_search is None:  # time marching's states are the integrator's: nothing to polish
        polish_search = method != "time_marching" and bool(cfg["gap"].get("polish_searches", False))
    gm = importlib.import_module(f"{pkg}.gap.model")
    gd = importlib.import_module(f"{pkg}.gap.diagnosis")
    fit = ds["friction_fit"] if pkg == "contactid" else _reference_fit(ds["friction_fit"])
    model = gm.identified_model(cfg["structure"], ds["linear_modes"], ds["modal"], fit)
    K = cfg["nonlinear"]["n_harmonics"]
    records = {c: importlib.import_module(f"{pkg}.gap.records").record_harmonics(r, c, K) for c, r in raw.items()}
    # linear_stage and random_test_delays live in gap.localise now (in gap.diagnosis at REFERENCE)
    gl = gd if hasattr(gd, "linear_stage") else importlib.import_module(f"{pkg}.gap.localise")
    lin = gl.linear_stage(model, ds["frf"], ds["modal"])
    gap = (
        {**cfg["gap"], "candidates": ["multi_asperity_friction", "preload_drift"], "max_evaluations": 3}
        if warm_up
        else cfg["gap"]
    )
    gap = {**gap, "polish_searches": bool(polish_search)}
    settings = gd.GapSettings.from_config(gap, cfg["seed"], K)
    if pkg == "contactid":
        numerics = Numerics(
            steady_state=method,
            closed_contact_hb=DEFAULT.closed_contact_hb,
            settling_tol=DEFAULT.settling_tol if settle_tol is None else settle_tol,
            polish_searches=bool(polish_search),
            search=search,
            memo=memo,
        )
        settings = dataclasses.replace(settings, numerics=numerics)
    fit_settings = importlib.import_module(f"{pkg}.friction_fit").settings_from_config(cfg["friction"])
    t0 = time.perf_counter()
    kw = {"workers": workers} if workers > 1 else {}
    if pkg == "contactid":
        kw["channel_delays"] = gl.random_test_delays(ds["frf"], ds["modal"])
    d = gd.diagnose(model, records, cfg["nonlinear"]["calibration_case"], settings, fit_settings, lin, **kw)
    return d, time.perf_counter() - t0


def _gaps(d) -> dict:
    return {"before": d.where["heldout_gap_before"], **{r["effect"]: r["heldout_gap_after"] for r in d.ranking}}


def _agreement(a, b) -> dict:
    """Verdict, ranking order and held-out gaps (before and after each candidate) of two diagnoses."""
    ga, gb_ = _gaps(a), _gaps(b)
    rel = max(abs(gb_[k] / ga[k] - 1) for k in ga if np.isfinite(ga[k]) and np.isfinite(gb_.get(k, np.nan)))
    return {
        "same_verdict": a.verdict == b.verdict,
        "same_ranking": [r["effect"] for r in a.ranking] == [r["effect"] for r in b.ranking],
        "max_rel_gap_difference": float(rel),
        "verdicts": [a.verdict, b.verdict],
        "rankings": [[r["effect"] for r in a.ranking], [r["effect"] for r in b.ranking]],
        "heldout_gaps": [ga, gb_],
    }


def compare(label, ds, raw, cfg, with_reference=False, scatter=False, tight=None) -> dict:
    """The diagnosis now (harmonic balance, memos, residual searches) in one process and with two workers, against
    the plain diagnosis in the same process: every steady state by time marching, no memos, the searches on the gap
    alone (the diagnosis as issue 14 found it, on today's models and library). Also the same plain run with the
    residual searches (what the solver alone changes: verdict, ranking, held-out gaps); with ``scatter``, that run at
    half and at double its settling tolerance (the reference's own scatter); with ``tight`` (a settling tolerance),
    that run and the polished-search diagnosis both at it; with ``with_reference``, the package at
    REFERENCE (its friction kernel is the old slip-limit one: its gaps do not compare)."""
    run("contactid", "harmonic_balance", True, ds, raw, cfg, warm_up=True)  # compile or load every kernel once
    # ... in the two worker processes too: their first candidates otherwise load every kernel and import what the
    # package imports lazily (the first two-worker diagnosis of the default data took 4.1 s, the next ones 2.4 s)
    run("contactid", "harmonic_balance", True, ds, raw, cfg, warm_up=True, workers=2)
    new, t_new = run("contactid", "harmonic_balance", True, ds, raw, cfg)
    two, t_two = run("contactid", "harmonic_balance", True, ds, raw, cfg, workers=2)
    plain, t_plain = run("contactid", "time_marching", False, ds, raw, cfg, search="gap")
    marched, t_marched = run("contactid", "time_marching", False, ds, raw, cfg)
    configured = bool(cfg["gap"].get("polish_searches", False))
    other, t_other = run("contactid", "harmonic_balance", True, ds, raw, cfg, polish_search=not configured)
    row = {
        "data": label,
        "seconds_now": t_new,
        "seconds_two_workers": t_two,
        "seconds_plain": t_plain,
        "seconds_time_marching_residual_search": t_marched,
        "ratio": t_plain / t_new,
        "ratio_two_workers": t_plain / t_two,
        "polish_searches": configured,
        "seconds_other_polish_setting": t_other,
        "solver": _agreement(marched, new),
        "other_polish_setting": _agreement(marched, other),
        "search": _agreement(plain, new),
        "two_workers": _agreement(new, two),
    }
    if scatter:
        tol = DEFAULT.settling_tol
        half, _ = run("contactid", "time_marching", False, ds, raw, cfg, settle_tol=0.5 * tol)
        double, _ = run("contactid", "time_marching", False, ds, raw, cfg, settle_tol=2.0 * tol)
        row["reference_scatter"] = {
            "half_tolerance": _agreement(marched, half),
            "double_tolerance": _agreement(marched, double),
        }
    if tight is not None:
        ref_t, t_ref_t = run("contactid", "time_marching", False, ds, raw, cfg, settle_tol=tight)
        pol_t, t_pol_t = run("contactid", "harmonic_balance", True, ds, raw, cfg, polish_search=True, settle_tol=tight)
        row["tight_tolerance"] = {
            "tolerance": tight,
            "seconds_time_marching": t_ref_t,
            "seconds_polished_searches": t_pol_t,
            "polished_searches": _agreement(ref_t, pol_t),
        }
    if with_reference:
        run("contactid_ref", None, None, ds, raw, cfg, warm_up=True)
        old, t_old = run("contactid_ref", None, None, ds, raw, cfg)
        row["seconds_reference"] = t_old
        row["reference"] = {"verdict": old.verdict, "ranking": [r["effect"] for r in old.ranking]}
    sv, se, so = row["solver"], row["search"], row["other_polish_setting"]
    now_is = "every searched state polished" if configured else "periodic states in the searches"
    other_is = "periodic states in the searches" if configured else "every searched state polished"
    print(
        f"{label}: now ({now_is}) {t_new:.1f} s (two workers {t_two:.1f} s), plain time marching {t_plain:.1f} s: "
        f"x{row['ratio']:.1f} (x{row['ratio_two_workers']:.1f} with two workers)"
        + (f"; {REFERENCE} {row['seconds_reference']:.1f} s" if with_reference else "")
        + f"\n  solver (time marching with the same searches, {t_marched:.1f} s): verdict "
        f"{'same' if sv['same_verdict'] else 'DIFFERENT'}, ranking {'same' if sv['same_ranking'] else 'DIFFERENT'}, "
        f"held-out gaps within {sv['max_rel_gap_difference']:.2%}; {other_is} "
        f"({t_other:.1f} s): held-out gaps within {so['max_rel_gap_difference']:.2%}, ranking "
        f"{'same' if so['same_ranking'] else 'DIFFERENT'}"
        f"\n  searches (plain): verdict {se['verdicts'][0]} / {se['verdicts'][1]}, ranking "
        f"{'same' if se['same_ranking'] else 'different'}, held-out gaps within {se['max_rel_gap_difference']:.1%}; "
        f"two workers: {'same' if row['two_workers']['same_ranking'] else 'OTHER'} ranking",
        flush=True,
    )
    if scatter:
        rs = row["reference_scatter"]
        half, double = (rs[k]["max_rel_gap_difference"] for k in ("half_tolerance", "double_tolerance"))
        print(
            "  the time-marching diagnosis itself at half / double its settling tolerance: held-out gaps within "
            f"{half:.2%} / {double:.2%}"
            f", verdict {'same' if all(a['same_verdict'] for a in rs.values()) else 'DIFFERENT'}",
            flush=True,
        )
    if tight is not None:
        tt = row["tight_tolerance"]
        a = tt["polished_searches"]
        print(
            f"  at the settling tolerance {tight:g}: time marching {tt['seconds_time_marching']:.1f} s, every searched "
            f"state polished {tt['seconds_polished_searches']:.1f} s: verdict "
            f"{'same' if a['same_verdict'] else 'DIFFERENT'}, ranking {'same' if a['same_ranking'] else 'DIFFERENT'}"
            f", held-out gaps within {a['max_rel_gap_difference']:.3%}",
            flush=True,
        )
    for name, a in (("solver", sv), ("searches", se)):
        if not a["same_ranking"]:
            print(f"  {name}: plain {a['rankings'][0]}\n  {' ' * len(name)}  now   {a['rankings'][1]}")
    return row


def main():
    from contactid.gap.workers import _pool

    _pool(2)  # forked now, before numba's parallel threads start in this process (the runs with two workers)
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    with_reference = "--with-reference" in sys.argv
    scatter = "--reference-scatter" in sys.argv
    tight = float(sys.argv[sys.argv.index("--tight-tolerance") + 1]) if "--tight-tolerance" in sys.argv else None
    if with_reference:
        reference_package()
    only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else None
    rows = []
    if only in (None, "default"):
        rows.append(compare("default (effect-free)", *default_data(cfg), cfg, with_reference, scatter, tight))
    for effect, magnitude in EFFECTS.items():
        if only in (None, effect):
            rows.append(
                compare(
                    f"{effect} {magnitude:g}",
                    *effect_data(cfg, effect, magnitude),
                    cfg,
                    with_reference,
                    scatter,
                    tight,
                )
            )
    worst = max(r["seconds_now"] for r in rows)
    ratio = min(r["ratio"] for r in rows)
    ratio2 = min(r["ratio_two_workers"] for r in rows)
    solver_ok = all(r["solver"]["same_verdict"] and r["solver"]["same_ranking"] for r in rows)
    print(
        f"slowest diagnosis {worst:.1f} s (goal 15 s: {'met' if worst <= 15 else 'NOT met'}); smallest ratio "
        f"x{ratio:.1f} in one process, x{ratio2:.1f} with two workers (goal 5: "
        f"{'met' if ratio >= 5 else 'met with two workers' if ratio2 >= 5 else 'NOT met'}); harmonic balance against "
        f"time marching with the same searches: {'same' if solver_ok else 'NOT the same'} verdicts and rankings, "
        f"held-out gaps within {max(r['solver']['max_rel_gap_difference'] for r in rows):.2%} (goal 0.1 %: "
        f"{'met' if solver_ok and max(r['solver']['max_rel_gap_difference'] for r in rows) <= 1e-3 else 'NOT met'}; "
        f"gap.polish_searches {str(not rows[0]['polish_searches']).lower()}: within "
        f"{max(r['other_polish_setting']['max_rel_gap_difference'] for r in rows):.2%}, slowest "
        f"{max(r['seconds_other_polish_setting'] for r in rows):.1f} s)"
    )
    if scatter:
        own = max(a["max_rel_gap_difference"] for r in rows for a in r["reference_scatter"].values())
        print(
            f"the time-marching reference's own held-out gaps move by up to {own:.2%} between half and double its "
            "settling tolerance: agreement with it can be asked only to that scale"
        )
    if tight is not None:
        worst_t = max(r["tight_tolerance"]["polished_searches"]["max_rel_gap_difference"] for r in rows)
        same_t = all(
            r["tight_tolerance"]["polished_searches"]["same_verdict"]
            and r["tight_tolerance"]["polished_searches"]["same_ranking"]
            for r in rows
        )
        print(
            f"at the settling tolerance {tight:g}, every searched state polished against time marching: "
            f"{'same' if same_t else 'NOT the same'} verdicts and rankings, held-out gaps within {worst_t:.3%} "
            f"(goal 0.1 %: {'met' if worst_t <= 1e-3 else 'NOT met'})"
        )
    if with_reference:
        ref1 = min(r["seconds_reference"] / r["seconds_now"] for r in rows)
        ref2 = min(r["seconds_reference"] / r["seconds_two_workers"] for r in rows)
        print(
            f"against {REFERENCE} (the package when issue 14 was taken up, its slip-limit friction kernel): smallest "
            f"ratio x{ref1:.1f} in one process, x{ref2:.1f} with two workers (as the gap_diagnosis rule runs it)"
        )
    CACHE.mkdir(parents=True, exist_ok=True)
    (CACHE / "gap_diagnosis.json").write_text(json.dumps(rows, indent=2, default=str))


if __name__ == "__main__":
    main()
