"""Development set from elsewhere (issue 55): the workflow on the records of a simulator written by other hands.

``../shared/foreign/<set>/`` holds a random test and three dual-sine records of the paper's test made by a simulator
that shares nothing with contactid (its own finite elements, reduction, damping, normal law, integrator and
measurement chain), the overlay that tells contactid what a user of it knows, and, for development, its truth
(``truth/truth.json``: the friction law of Eqs. 21-22, the normal stiffness at the preload, the stuck structure's
natural frequencies; ``truth/lc*.nc``: S, N, xi, eta on the records' time grid). Each set runs as measured records in
a copy of the project (``snakemake gap summary``, about 40 s), and every stage is scored against the truth: natural
frequencies, k_n, the contact forces and motions (NRMSE, mean removed, as summary.json's), the friction law's
parameters with their intervals, the records' check, the held-out gap, the verdict and the explanation against what
was done, whether they tell one story, the resolution, the pairs the records cannot isolate, and the law refitted with
the explained effects (results/gap/updated_model.json) against the truth. Printed, and written to
benchmarks/cache/foreign_records.json.

Usage: .venv/bin/python benchmarks/foreign_records.py [SET ...]   (default: every set under ../shared/foreign)
"""

import json
import sys
from pathlib import Path

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import measured_project, run_gap_summary
from contactid.gap.bench_scores import named_effects
from contactid.gap.story import one_story_holds
from independent_rig import contact_scores, contact_text

ROOT = Path(__file__).resolve().parents[1]
CACHE = ROOT / "benchmarks" / "cache"
FOREIGN = ROOT.parent / "shared" / "foreign"
FRICTION = {"mu": "mu", "kappa": "kappa", "e_t": "e_t_n_per_m", "e_f": "e_f_n_per_m", "k_c": "k_c_per_m"}


def project(name: str, folder: Path) -> Path:
    """A copy of the project whose config is config/config.yaml with the set's overlay merged over it (paths made
    absolute), as `snakemake --configfile` would read it."""
    from contactid.schema import merged_over

    overlay = yaml.safe_load((folder / "config.yaml").read_text())
    for block in [overlay["random_test"], *overlay["load_cases"].values()]:
        block["file"] = str((ROOT / block["file"]).resolve())
    cfg = merged_over(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()), overlay)
    return measured_project(CACHE / "foreign" / "projects" / name, cfg)


def score(name: str, proj: Path, folder: Path) -> dict:
    truth = json.loads((folder / "truth" / "truth.json").read_text())
    summary = json.loads((proj / "results" / "summary.json").read_text())
    diagnosis = json.loads((proj / "results" / "gap" / "diagnosis.json").read_text())
    law, fr = truth["friction_law_eq21_22"], summary["friction"]
    friction = {}
    for k, tk in FRICTION.items():
        row = {"identified": fr[k], "truth": law[tk], "error": fr[k] / law[tk] - 1}
        if k in (fr.get("intervals") or {}):
            lo, hi = fr["intervals"][k]
            row.update(interval=[lo, hi], covered=bool(lo <= law[tk] <= hi))
        mf = (fr.get("model_form_intervals") or {}).get(k)
        if mf:
            row.update(
                model_form_interval=mf["interval"],
                model_form_covered=bool(mf["interval"][0] <= law[tk] <= mf["interval"][1]),
            )
        friction[k] = row
    # k_n where the frequencies bind it, else its lower bound (the stiction block says which)
    bound = "k_n" not in summary["stiction"]
    k_n = summary["stiction"]["k_n_lower_bound" if bound else "k_n"]
    records = summary.get("records_check") or {}
    return {
        "data": name,
        "truth": truth["what_was_done"],
        "frequency_errors": [
            f / t - 1 for f, t in zip(summary["natural_frequencies_hz"], truth["natural_frequencies_hz"])
        ],
        "k_n_error": k_n / truth["normal_stiffness_at_preload_n_per_m"] - 1,
        "k_n_is_lower_bound": bound,
        "friction": friction,
        "validation_nrmse": summary["validation_nrmse"],
        "contact": contact_scores(proj, folder, float(truth["preload_n"])),
        "records_check": {
            "passed": records.get("passed"),
            "findings": [f["check"] for f in records.get("findings", [])],
        },
        "verdict": diagnosis["verdict"],
        "reason": diagnosis["reason"],
        "one_story": one_story_holds(diagnosis),
        "named": named_effects(diagnosis["explanation"]),
        "resolution": diagnosis["resolution"]["heldout_gap"],
        "not_isolable": [p["candidates"] for p in (diagnosis["resolution"].get("isolability") or {}).get("pairs", [])],
        "explained_law_errors": explained_law_errors(proj, law),
        "explained_law_intervals": explained_law_intervals(proj, law),
        "explanation": [
            (e["effect"], e.get("kind"), e["parameters"], e["heldout_gap_after"]) for e in diagnosis["explanation"]
        ],
        "heldout_gap_before": diagnosis["where"]["heldout_gap_before"],
        "remaining_gap": diagnosis["remaining_gap"]["heldout_gap"],
        "floor": (diagnosis.get("measured_floor") or {}).get("min_gap"),
    }


def explained_law_errors(proj: Path, law: dict) -> dict:
    """The law of the model the diagnosis arrives at (results/gap/updated_model.json) against the truth, where it
    differs from the chain's (an effect explained, or the damping at test level applied; {} otherwise), with e_0 at the
    preload."""
    from contactid.contact_laws import stiction_shear_stiffness

    path = proj / "results" / "gap" / "updated_model.json"
    updated = json.loads(path.read_text()) if path.exists() else {}
    if not updated.get("effects") and not (updated.get("damping_at_test_level") or {}).get("applied"):
        return {}
    out = {k: updated["friction"][k] / law[tk] - 1 for k, tk in FRICTION.items()}
    preload = float(yaml.safe_load((proj / "config" / "config.yaml").read_text())["structure"]["preload_n"])
    e0 = stiction_shear_stiffness(preload, law["e_f_n_per_m"], law["k_c_per_m"])
    return {**out, "e0": updated["friction"]["e0_at_preload"] / e0 - 1}


def explained_law_intervals(proj: Path, law: dict) -> dict:
    """Where the diagnosed model carries the damping at test level: the intervals of its law (rule test_damping's fit
    at the factor), {name: {interval, covered, relative half-width}} for mu and kappa, and e0 at the preload."""
    from contactid.contact_laws import stiction_shear_stiffness

    path = proj / "results" / "gap" / "updated_model.json"
    td = (json.loads(path.read_text()) if path.exists() else {}).get("damping_at_test_level") or {}
    if not td.get("applied") or "law_intervals" not in td:
        return {}
    preload = float(yaml.safe_load((proj / "config" / "config.yaml").read_text())["structure"]["preload_n"])
    truth = {k: law[FRICTION[k]] for k in ("mu", "kappa")}
    truth["e0"] = stiction_shear_stiffness(preload, law["e_f_n_per_m"], law["k_c_per_m"])
    out = {}
    for k, t in truth.items():
        lo, hi = td["e0_interval"] if k == "e0" else td["law_intervals"][k]
        mid = td["law"][k] if k != "e0" else stiction_shear_stiffness(preload, td["law"]["e_f"], td["law"]["k_c"])
        out[k] = {"interval": [lo, hi], "covered": bool(lo <= t <= hi), "halfwidth": (hi - lo) / 2 / abs(mid)}
    return out


def report(r: dict) -> None:
    f = r["friction"]
    print(
        f"{r['data']} (truth: {r['truth']}): frequencies within {max(abs(x) for x in r['frequency_errors']):.3%}, "
        f"k_n{' lower bound' if r['k_n_is_lower_bound'] else ''} {r['k_n_error']:+.1%}; friction "
        + ", ".join(
            f"{k} {v['error']:+.1%}" + ("" if "covered" not in v else f" ({'in' if v['covered'] else 'OUTSIDE'})")
            for k, v in f.items()
        )
        + "\n  contact: "
        + contact_text(r["contact"])
        + "\n  validation "
        + ", ".join(f"{c} {x:.2%}" for c, x in r["validation_nrmse"].items())
        + f"; records check {'passed' if r['records_check']['passed'] else 'FAILED'} {r['records_check']['findings']}"
        + f"\n  diagnosis: verdict {r['verdict']}; held-out gap {r['heldout_gap_before']:.4f} (floor "
        + (f"{r['floor']:.4f}" if r["floor"] is not None else "not measured")
        + f") -> remaining {r['remaining_gap']:.4f}; resolution {r['resolution']:.4f}; explanation "
        + (", ".join(f"{e} ({k}) {p} -> {g:.4f}" for e, k, p, g in r["explanation"]) or "none")
        + f"; one story: {r['one_story']}; not isolable: {r['not_isolable'] or 'none'}"
        + (
            "\n  the law of the model the diagnosis arrives at (updated_model.json): "
            + ", ".join(f"{k} {v:+.1%}" for k, v in r["explained_law_errors"].items())
            if r["explained_law_errors"]
            else ""
        )
        + (
            "; intervals "
            + ", ".join(
                f"{k} [{v['interval'][0]:.4g}, {v['interval'][1]:.4g}] ({'in' if v['covered'] else 'OUTSIDE'}, "
                f"half-width {v['halfwidth']:.1%})"
                for k, v in r["explained_law_intervals"].items()
            )
            if r.get("explained_law_intervals")
            else ""
        ),
        flush=True,
    )


def main():
    sets = sorted(p.name for p in FOREIGN.iterdir() if (p / "config.yaml").exists()) if FOREIGN.is_dir() else []
    names = sys.argv[1:] or sets
    if not names:
        raise SystemExit(f"benchmarks/foreign_records.py: no record sets under {FOREIGN}")
    rows = []
    for name in names:
        if name not in sets:
            raise SystemExit(f"benchmarks/foreign_records.py: unknown set {name!r}; give any of {', '.join(sets)}")
        folder = FOREIGN / name
        proj = project(name, folder)
        run_gap_summary(name, proj)
        rows.append(score(name, proj, folder))
        report(rows[-1])
    CACHE.mkdir(parents=True, exist_ok=True)
    (CACHE / "foreign_records.json").write_text(json.dumps(rows, indent=2, default=float))
    med = {k: float(np.median([abs(r["friction"][k]["error"]) for r in rows])) for k in FRICTION}
    print("median |error| over the sets: " + ", ".join(f"{k} {v:.1%}" for k, v in med.items()))


if __name__ == "__main__":
    main()
