"""Figures of the diagnosis (results/gap/*.png): one per view."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import xarray as xr


def _num(x) -> float:
    """A diagnosis.json number as a float (null, written for a non-finite value, as NaN)."""
    return float("nan") if x is None else float(x)


def _save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def stages(diag: dict, path: str):
    st = diag["where"]["stage"]
    fig, ax = plt.subplots(figsize=(6.5, 3.2))
    keys = list(st)
    ax.barh(keys, [100 * st[k] for k in keys], color="tab:red")
    ax.set_xscale("log")
    ax.set_xlabel("relative disagreement (%)")
    ax.set_title("Gap by stage of the chain (identified model vs records)")
    _save(fig, path)


def harmonics(ds: xr.Dataset, path: str):
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.3))
    for c in ds["case"].values:
        axes[0].semilogy(ds["harmonic"], 100 * ds["gap_by_harmonic"].sel(case=c), "o-", label=str(c))
    axes[0].set_xlabel("harmonic of the test frequency")
    axes[0].set_ylabel("residual / |A| (%)")
    axes[0].set_title("by harmonic (odd: driven; even: asymmetry)")
    axes[0].legend()
    x = np.arange(ds.sizes["sensor"])
    for i, c in enumerate(ds["case"].values):
        axes[1].bar(x + 0.25 * i, 100 * ds["gap_by_sensor"].sel(case=c), 0.25, label=str(c))
    axes[1].set_xticks(x + 0.25, [str(s) for s in ds["sensor"].values])
    axes[1].set_ylabel("gap (%)")
    axes[1].set_title("by sensor and load case")
    _save(fig, path)


def cycle(ds: xr.Dataset, path: str):
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.3))
    x = np.arange(ds.sizes["cycle_part"])
    for i, c in enumerate(ds["case"].values):
        axes[0].bar(x + 0.25 * i, 100 * ds["gap_by_cycle_part"].sel(case=c), 0.25, label=str(c))
    axes[0].set_xticks(x + 0.25, [p.replace("_", "\n") for p in ds["cycle_part"].values])
    axes[0].set_ylabel("rms residual / rms acceleration (%)")
    axes[0].set_title("by part of the cycle (driving point)")
    axes[0].legend()
    et, en = ds["energy_tangential"].values, ds["energy_normal"].values
    x = np.arange(ds.sizes["case"])
    axes[1].bar(x - 0.3, 1e3 * et[:, 0], 0.2, label="tangential, identified")
    axes[1].bar(x - 0.1, 1e3 * et[:, 1], 0.2, label="tangential, model")
    axes[1].bar(x + 0.1, 1e3 * en[:, 0], 0.2, label="normal, identified")
    axes[1].bar(x + 0.3, 1e3 * en[:, 1], 0.2, label="normal, model")
    axes[1].set_xticks(x, [str(c) for c in ds["case"].values])
    axes[1].set_ylabel("energy per cycle (mJ)")
    axes[1].set_title("dissipation in each direction")
    axes[1].legend(fontsize=7)
    _save(fig, path)


def force_state(ds: xr.Dataset, path: str):
    n = ds.sizes["case"]
    fig, axes = plt.subplots(2, n, figsize=(3.3 * n, 5.6), squeeze=False)
    for i, c in enumerate(ds["case"].values):
        m = ds.sel(case=c)
        for row, (x, y, r, lab) in enumerate(
            (("xi", "xi_dot", "S_residual", "S"), ("eta", "eta_dot", "N_residual", "N"))
        ):
            ax = axes[row, i]
            sc = ax.scatter(1e6 * m[f"map_{x}"], 1e3 * m[f"map_{y}"], c=m[f"map_{r}"], cmap="coolwarm", s=6)
            fig.colorbar(sc, ax=ax, label=f"{lab} residual (N)")
            ax.set_xlabel(f"{x} (um)")
            ax.set_ylabel(f"{y} (mm/s)")
            ax.set_title(f"{c}: {lab} identified - law")
    _save(fig, path)


def ranking(diag: dict, path: str):
    rows = diag["ranking"]
    fig, ax = plt.subplots(figsize=(7, 3.6))
    names = [r["effect"] for r in rows]
    after = np.array([100 * _num(r["heldout_gap_after"]) for r in rows])
    lo = np.array([100 * _num(r["heldout_gap_after_interval"][0]) for r in rows])
    hi = np.array([100 * _num(r["heldout_gap_after_interval"][1]) for r in rows])
    y = np.arange(len(rows))
    ax.barh(
        y, after, xerr=[np.maximum(after - lo, 0), np.maximum(hi - after, 0)], color="tab:blue", label="with the effect"
    )
    if rows:
        ax.axvline(100 * rows[0]["heldout_gap_before"], color="k", ls="--", label="identified model (before)")
    ax.set_yticks(y, names)
    ax.invert_yaxis()
    finite = hi[np.isfinite(hi)]
    ax.set_xlim(
        0, 1.15 * max(finite.max() if finite.size else 1.0, 100 * rows[0]["heldout_gap_before"] if rows else 1.0)
    )
    ax.set_xlabel("held-out gap (%)")
    ax.set_title(f"Candidates ranked; verdict: {diag['verdict']}")
    ax.legend(fontsize=7)
    _save(fig, path)


def shrink(diag: dict, path: str):
    """Held-out gap before and after for the winner and the runner-up, per load case and per harmonic."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    sh = diag.get("shrink", {})
    cases = list(next(iter(sh.values()))["by_case"]) if sh else []
    x = np.arange(len(cases))
    first = True
    for i, (label, v) in enumerate(sh.items()):
        bc = v["by_case"]
        if first:
            b = np.array([100 * bc[c]["before"] for c in cases])
            axes[0].bar(x - 0.27, b, 0.27, color="0.6", label="identified model")
            first = False
        a = np.array([100 * bc[c]["after"] for c in cases])
        lo = np.array([100 * bc[c]["after_interval"][0] for c in cases])
        hi = np.array([100 * bc[c]["after_interval"][1] for c in cases])
        axes[0].bar(
            x + 0.27 * i,
            a,
            0.27,
            yerr=[np.maximum(a - lo, 0), np.maximum(hi - a, 0)],
            label=f"+ {v['effect']} ({label.replace('_', '-')})",
        )
        axes[1].semilogy(
            np.arange(1, len(v["by_harmonic"]["after"]) + 1),
            100 * np.array(v["by_harmonic"]["after"]),
            "o-",
            label=f"+ {v['effect']}",
        )
    if sh:
        v = next(iter(sh.values()))
        axes[1].semilogy(
            np.arange(1, len(v["by_harmonic"]["before"]) + 1),
            100 * np.array(v["by_harmonic"]["before"]),
            "s--",
            color="0.4",
            label="identified model",
        )
    axes[0].set_xticks(x, cases)
    axes[0].set_ylabel("held-out gap (%)")
    axes[0].set_title("before and after, per held-out case (95 % bootstrap)")
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel("harmonic")
    axes[1].set_ylabel("residual / |A| (%)")
    axes[1].set_title("per harmonic (held-out cases)")
    axes[1].legend(fontsize=7)
    _save(fig, path)


def explanation(diag: dict, path: str):
    """The additive explanation as a waterfall: the identified model's held-out gap, what each added effect
    removes (its share of the gap's power), what remains; the identification's floor (gap.min_gap) drawn."""
    steps = diag.get("explanation") or []
    left = diag.get("remaining_gap") or {}
    before = diag["where"]["heldout_gap_before"]
    fig, ax = plt.subplots(figsize=(6.5, 3.4))
    labels, bottoms, heights, colors = ["identified model"], [0.0], [100 * before], ["0.5"]
    for s in steps:
        labels.append(f"+ {s['effect']}\n({100 * s['share']:.0f} % of the power)")
        bottoms.append(100 * s["heldout_gap_after"])
        heights.append(100 * (s["heldout_gap_before"] - s["heldout_gap_after"]))
        colors.append("tab:green")
    remaining = left.get("heldout_gap", before)
    labels.append(f"remaining\n({left.get('place', diag['where'].get('place', '?'))})")
    bottoms.append(0.0)
    heights.append(100 * remaining)
    colors.append("tab:red" if not left.get("at_floor") else "tab:blue")
    x = np.arange(len(labels))
    ax.bar(x, heights, bottom=bottoms, color=colors, width=0.6)
    if left.get("floor") is not None:
        ax.axhline(
            100 * left["floor"], color="k", ls=":", lw=1, label=f"floor gap.min_gap = {100 * left['floor']:.2g} %"
        )
        ax.legend(fontsize=8, loc="upper right")
    ax.set_xticks(x, labels, fontsize=8)
    ax.set_ylabel("held-out gap (%)")
    ax.set_title(
        "The held-out gap explained step by step" if steps else "No effect explains the held-out gap materially"
    )
    _save(fig, path)


def all_figures(diagnosis_path: str, gap_path: str, out: dict):
    diag = json.load(open(diagnosis_path))
    ds = xr.open_dataset(gap_path, engine="netcdf4")
    stages(diag, out["stages"])
    harmonics(ds, out["harmonics"])
    cycle(ds, out["cycle"])
    force_state(ds, out["force_state"])
    ranking(diag, out["ranking"])
    shrink(diag, out["shrink"])
    explanation(diag, out["explanation"])
    ds.close()
