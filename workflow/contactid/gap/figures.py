r"""Figures of the diagnosis (results/gap/): one per question, drawn at the report's text width.

Text of at least 8 pt (:mod:`contactid.print_style`). The report includes the gap by stage, the candidates ranked,
before and after per held-out case and the step-by-step explanation (PDF at ``\textwidth``); the diagnostic views (by
harmonic and sensor, by part of the cycle, the force-state maps) are figures of their own in results/gap/.
"""

from __future__ import annotations

import json

import numpy as np
import xarray as xr

from .. import print_style as ps
from .place import DEFAULT_PLACE, PlaceThresholds, never_opens

W = ps.TEXT_WIDTH_IN
XI_UM, XI_DOT, ETA_UM, ETA_DOT = r"$\xi$ ($\mu$m)", r"d$\xi$/dt (mm/s)", r"$\eta$ ($\mu$m)", r"d$\eta$/dt (mm/s)"

# the stages' readable labels (diagnosis.json where.stage keys)
STAGE_LABELS = {
    "accelerations": "sensor accelerations, all cases",
    "generalized_coordinates": "generalized coordinates",
    "identification_residual": "identification misfit at ω and 3ω",
    "contact_force_S": "contact force S (friction law)",
    "contact_force_N": "contact force N (elastic normal law)",
    "energy_tangential": "energy, tangential direction",
    "energy_normal": "energy, normal direction",
    "frf_frequency": "random test: natural frequencies",
    "frf_peak_amplitude": "random test: FRF peaks",
    "open_fraction": "contact open (share of the cycle)",
}
HELDOUT = "heldout"


def _num(x) -> float:
    """Return a diagnosis.json number as a float (null, written for a non-finite value, as NaN)."""
    return float("nan") if x is None else float(x)


def _name(effect: str) -> str:
    """Return a candidate's name as words: contact_separation -> contact separation."""
    return str(effect).replace("_", " ")


def min_gap(diag: dict, default: float = 0.006) -> float:
    """Return gap.min_gap of the diagnosis (its remaining gap's floor).

    Parameters
    ----------
    diag
        The diagnosis (diagnosis.json; its ``remaining_gap.floor``).
    default
        The floor where the diagnosis states none [-].

    Returns
    -------
    floor : float
        The relative held-out gap below which nothing is explained [-].
    """
    return float((diag.get("remaining_gap") or {}).get("floor", default))


def stage_rows(diag: dict, thresholds: PlaceThresholds = DEFAULT_PLACE) -> list[tuple[str, str, float, tuple]]:
    """Return the stage figure's rows: (key, label, value, (threshold, its name) or ()).

    The held-out gap first (compared with gap.min_gap), then each stage; the localisation's thresholds where a stage is
    compared with one.

    Parameters
    ----------
    diag
        The diagnosis (diagnosis.json: ``where``'s held-out gap, stages and identification noise,
        ``remaining_gap``).
    thresholds
        The localisation's thresholds (gap.place).

    Returns
    -------
    rows : list[tuple[str, str, float, tuple]]
        Per row the stage's key, its label, its relative value [-] (NaN where not finite) and (its threshold [-],
        the threshold's name), or () where it is compared with none.
    """
    w = diag["where"]
    rows = [(HELDOUT, "held-out gap (accelerations)", _num(w["heldout_gap_before"]), (min_gap(diag), "gap.min_gap"))]
    noise = list((w.get("identification_noise") or {}).values())
    limits = {"contact_force_N": (thresholds.normal_limit, "normal_limit")}
    if noise:
        limits["identification_residual"] = (
            thresholds.residual_factor * float(np.median(noise)),
            f"{thresholds.residual_factor:g} × its scatter",
        )
    for key, value in w["stage"].items():
        rows.append((key, STAGE_LABELS.get(key, _name(key)), _num(value), limits.get(key, ())))
    return rows


def _two_digits(v: float) -> str:
    """Return a number to two significant digits as people write it: 280, 17, 0.64, 0.0007 (not 2.8e+02 or 7e-04).

    Below 1e-4 in powers of ten (1.2e-05).
    """
    if not np.isfinite(v):
        return "n/a"
    if v == 0:
        return "0"
    if abs(v) < 1e-4:
        return f"{v:.2g}"
    return f"{float(f'{v:.2g}'):.12f}".rstrip("0").rstrip(".")


def _stage_value_text(v: float, limit: tuple) -> str:
    """Return the stage figure's right-hand column: the value (%), and the threshold it is compared with."""
    text = "0" if v == 0 else ("n/a" if not np.isfinite(v) else f"{_two_digits(v)} %")
    return text + (f"  ({limit[1]}: {_two_digits(100 * limit[0])} %)" if limit else "")


@ps.print_figure
def stages(diag: dict, png: str, pdf: str | None = None, thresholds: PlaceThresholds = DEFAULT_PLACE) -> None:
    """Draw the gap at each stage of the chain (%, log axis; a zero value written as 0, its bar absent).

    With the threshold each is compared with (black mark, and in the right-hand column): gap.min_gap for the held-out
    gap, the localisation's (gap.place) for the stages it tests.

    Parameters
    ----------
    diag
        The diagnosis (diagnosis.json).
    png
        The figure's PNG file.
    pdf
        Its PDF file, or None.
    thresholds
        The localisation's thresholds (gap.place).
    """
    plt = ps.pyplot()
    rows = stage_rows(diag, thresholds)
    values = np.array([100 * v for _, _, v, _ in rows])
    limits = [100 * t[0] for *_, t in rows if t]
    positive = values[np.isfinite(values) & (values > 0)]
    lo = 10 ** np.floor(np.log10(min(positive.min() if positive.size else 1e-3, *limits)))
    hi = 10 ** np.ceil(np.log10(max(positive.max() if positive.size else 1.0, *limits)) + 0.2)
    fig, ax = plt.subplots(figsize=(W, 0.24 * len(rows) + 1.1))
    y = np.arange(len(rows))
    ax.barh(y, np.where(values > 0, values - lo, 0), left=lo, height=0.6, color="tab:red", alpha=0.8)
    for yi, v, (key, _, _, limit) in zip(y, values, rows):
        ax.text(1.02, yi, _stage_value_text(v, limit), transform=ax.get_yaxis_transform(), va="center")
        if v == 0:
            ax.text(lo * 1.1, yi, "0", va="center", gid=f"zero:{key}")
        if limit:
            ax.plot([100 * limit[0]] * 2, [yi - 0.45, yi + 0.45], color="k", lw=1.8, gid=f"threshold:{key}")
    ax.plot([], [], color="k", lw=1.8, label="threshold the value is compared with (value in brackets)")
    ax.set_xscale("log")
    ax.set_xlim(lo, hi)
    ps.plain_log_ticks(ax.xaxis)
    ax.set_yticks(y, [label for _, label, _, _ in rows])
    ax.set_ylim(len(rows) - 0.5, -0.5)
    ax.set_xlabel("relative disagreement, identified model against the records (%)")
    ax.set_title("The gap at each stage of the chain")
    fig.legend(loc="lower center", frameon=False)
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout(rect=(0, 0.3 / fig.get_size_inches()[1], 1, 1))
    ps.save(fig, png, pdf)


@ps.print_figure
def harmonics(ds: xr.Dataset, png: str, pdf: str | None = None) -> None:
    """Draw the gap by harmonic (log) and by sensor, per load case.

    Parameters
    ----------
    ds
        The diagnosis's gap.nc (``gap_by_harmonic`` and ``gap_by_sensor``, relative, over case, harmonic and
        sensor).
    png
        The figure's PNG file.
    pdf
        Its PDF file, or None.
    """
    plt = ps.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(W, 2.9))
    for c in ds["case"].values:
        axes[0].semilogy(ds["harmonic"], 100 * ds["gap_by_harmonic"].sel(case=c), "o-", ms=3, label=str(c))
    ps.plain_log_ticks(axes[0].yaxis)
    axes[0].set_xticks(ds["harmonic"].values)
    axes[0].set_xlabel("harmonic of the test frequency")
    axes[0].set_ylabel("residual / |A| (%)")
    axes[0].set_title("By harmonic (odd: driven; even: asymmetry)")
    axes[0].legend()
    x = np.arange(ds.sizes["sensor"])
    n = ds.sizes["case"]
    for i, c in enumerate(ds["case"].values):
        axes[1].bar(x + (i - (n - 1) / 2) / (n + 1), 100 * ds["gap_by_sensor"].sel(case=c), 1 / (n + 1), label=str(c))
    axes[1].set_xticks(x, [str(s) for s in ds["sensor"].values])
    axes[1].set_xlabel("sensor")
    axes[1].set_ylabel("gap (%)")
    axes[1].set_title("By sensor and load case")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    ps.save(fig, png, pdf)


@ps.print_figure
def cycle(ds: xr.Dataset, png: str, pdf: str | None = None) -> None:
    """Draw the gap by part of the cycle and the energy dissipated per cycle in each direction, per load case.

    Parameters
    ----------
    ds
        The diagnosis's gap.nc (``gap_by_cycle_part``, relative, over case and cycle_part; ``energy_tangential`` and
        ``energy_normal`` in J over case and source: identified, model).
    png
        The figure's PNG file.
    pdf
        Its PDF file, or None.
    """
    plt = ps.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(W, 3.0))
    x = np.arange(ds.sizes["cycle_part"])
    n = ds.sizes["case"]
    for i, c in enumerate(ds["case"].values):
        axes[0].bar(x + (i - (n - 1) / 2) / (n + 1), 100 * ds["gap_by_cycle_part"].sel(case=c), 1 / (n + 1), label=c)
    axes[0].set_xticks(x, [p.replace("_", "\n") for p in ds["cycle_part"].values])
    axes[0].set_ylabel("rms residual / rms acceleration (%)")
    axes[0].set_title("By part of the cycle (driving point)")
    axes[0].legend()
    et, en = ds["energy_tangential"].values, ds["energy_normal"].values
    x = np.arange(n)
    for k, (e, d, j) in enumerate(((et, "tangential", 0), (et, "tangential", 1), (en, "normal", 0), (en, "normal", 1))):
        who = ("identified", "model")[j]
        axes[1].bar(x + 0.2 * k - 0.3, 1e3 * e[:, j], 0.2, label=f"{d}, {who}", color=f"C{k}")
    axes[1].set_xticks(x, [str(c) for c in ds["case"].values])
    axes[1].set_ylabel("energy per cycle (mJ)")
    axes[1].set_title("Dissipation in each direction")
    axes[1].legend()
    for ax in axes:
        ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    ps.save(fig, png, pdf)


@ps.print_figure
def force_state(ds: xr.Dataset, png: str, pdf: str | None = None) -> None:
    """Draw the residual force-state maps over one period, one colour scale per row, centred on zero.

    S identified - friction law over (xi, dxi/dt), N identified - the best elastic normal law over (eta, deta/dt).

    Parameters
    ----------
    ds
        The diagnosis's gap.nc (the ``map_*`` variables over case and phase: xi and eta in m, their rates in m/s,
        the residual forces in N).
    png
        The figure's PNG file.
    pdf
        Its PDF file, or None.
    """
    plt = ps.pyplot()
    n = ds.sizes["case"]
    fig, axes = plt.subplots(2, n, figsize=(W, 5.0), squeeze=False, layout="constrained")
    specs = (("xi", "xi_dot", "S_residual", "S", XI_UM, XI_DOT), ("eta", "eta_dot", "N_residual", "N", ETA_UM, ETA_DOT))
    for row, (x, y, r, force, xl, yl) in enumerate(specs):
        vmax = float(np.nanmax(np.abs(ds[f"map_{r}"].values))) or 1.0
        for i, c in enumerate(ds["case"].values):
            m, ax = ds.sel(case=c), axes[row, i]
            sc = ax.scatter(1e6 * m[f"map_{x}"], 1e3 * m[f"map_{y}"], c=m[f"map_{r}"], cmap="coolwarm", s=5)
            sc.set_clim(-vmax, vmax)
            ax.set_xlabel(xl)
            if i == 0:
                ax.set_ylabel(yl)
            ax.set_title(f"{c}: {force} identified − law", fontsize=8.5)
            ax.grid(alpha=0.3)
        fig.colorbar(sc, ax=list(axes[row]), label=f"{force} residual (N)", pad=0.02)
    ps.save(fig, png, pdf)


def ranking_bars(diag: dict) -> list[dict]:
    """Return the ranking figure's bars: per candidate its held-out gap after (%) and bootstrap interval.

    A candidate that does not lower the held-out gap (after >= before) is clipped at before and marked no effect.

    Parameters
    ----------
    diag
        The diagnosis (diagnosis.json; its ``ranking``).

    Returns
    -------
    bars : list[dict]
        Per candidate: "effect", "end" (where the bar ends) [%], "low" and "high" (the interval's ends) [%],
        "no_effect", "diverged" and "reduction" (the held-out gap's, relative to before) [-].
    """
    out = []
    for r in diag["ranking"]:
        before, after = 100 * _num(r["heldout_gap_before"]), 100 * _num(r["heldout_gap_after"])
        lo, hi = (100 * _num(v) for v in r["heldout_gap_after_interval"])
        no_effect = bool(np.isfinite(after) and after >= before)
        out.append(
            {
                "effect": r["effect"],
                "end": before if no_effect else after,
                "low": lo,
                "high": hi,
                "no_effect": no_effect,
                "diverged": not np.isfinite(after),
                "reduction": 1 - after / before if before > 0 else float("nan"),
            }
        )
    return out


@ps.print_figure
def ranking(diag: dict, png: str, pdf: str | None = None) -> None:
    """Draw the candidates ranked: each one's held-out gap after (bar, 95 % bootstrap interval).

    The gap before, the identification's floor gap.min_gap (below it the verdict is none) and the records' scatter as
    lines; a candidate with no effect ends at before, marked.

    Parameters
    ----------
    diag
        The diagnosis (diagnosis.json).
    png
        The figure's PNG file.
    pdf
        Its PDF file, or None.
    """
    plt = ps.pyplot()
    bars, w = ranking_bars(diag), diag["where"]
    before, floor, scatter = 100 * _num(w["heldout_gap_before"]), 100 * min_gap(diag), 100 * _num(w["record_scatter"])
    fig, ax = plt.subplots(figsize=(W, 0.3 * len(bars) + 1.5))
    ends = [before, floor] + [b["high"] for b in bars if np.isfinite(b["high"]) and not b["no_effect"]]
    right = 1.12 * max(ends)
    for y, b in enumerate(bars):
        if b["diverged"]:
            ax.text(0.01 * right, y, "prediction diverged", va="center", fontsize=8)
            continue
        if b["no_effect"]:
            ax.barh(y, b["end"], 0.6, color="0.85", edgecolor="0.5", hatch="//", lw=0.5, gid=f"bar:{b['effect']}")
            ax.text(0.02 * right, y, "no effect", va="center", fontsize=8, gid=f"no_effect:{b['effect']}")
            continue
        err = [[max(b["end"] - b["low"], 0)], [max(b["high"] - b["end"], 0)]]
        ax.barh(y, b["end"], 0.6, xerr=err, color="tab:blue", capsize=2, gid=f"bar:{b['effect']}")
        # inside the bar where it is long enough to hold the label, else beside its whisker (a winner near the floor)
        inside = b["end"] >= 0.15 * right
        x = 0.02 * right if inside else max(b["end"], b["high"] if np.isfinite(b["high"]) else 0.0) + 0.01 * right
        ax.text(
            x,
            y,
            f"−{100 * b['reduction']:.0f} %",
            va="center",
            color="white" if inside else "black",
            fontsize=8,
            gid=f"reduction:{b['effect']}",
        )
    # the candidates are tried on the model diagnosed: the chain's, or the updated one where an update was accepted
    updated = any(st.get("effect") == "model_updating" for st in diag.get("explanation") or [])
    model = "updated model" if updated else "identified model"
    ax.axvline(before, color="k", ls="--", lw=1.2, label=f"before ({model}): {_two_digits(before)} %")
    ax.axvline(floor, color="tab:red", ls=":", lw=1.5, label=f"gap.min_gap: {_two_digits(floor)} %")
    ax.axvline(scatter, color="0.4", ls="-.", lw=1.0, label=f"records' scatter: {scatter:.1g} %")
    ax.set_yticks(range(len(bars)), [_name(b["effect"]) for b in bars])
    ax.set_ylim(len(bars) - 0.4, -0.6)
    ax.set_xlim(0, right)
    ax.set_xlabel("held-out gap with the candidate added (%), 95 % bootstrap interval")
    ax.set_title(f"Candidates ranked; verdict: {_name(diag['verdict'])}")
    fig.legend(loc="lower center", ncol=3, frameon=False)
    fig.tight_layout(rect=(0, 0.3 / fig.get_size_inches()[1], 1, 1))
    ps.save(fig, png, pdf)


def _shrink_by_case(ax, sh: dict, floor: float) -> None:
    """Draw before (grey) and after each of the winner and the runner-up, per held-out case, 95 % bootstrap."""
    cases = list(next(iter(sh.values()))["by_case"])
    x = np.arange(len(cases))
    width = 0.8 / (len(sh) + 1)

    def bar(k, values, intervals, **kw):
        v = 100 * np.array(values)
        lo, hi = (100 * np.array([i[j] for i in intervals]) for j in (0, 1))
        ax.bar(x + (k - len(sh) / 2) * width, v, width, yerr=[np.maximum(v - lo, 0), np.maximum(hi - v, 0)], **kw)

    bc = next(iter(sh.values()))["by_case"]
    bar(0, [bc[c]["before"] for c in cases], [bc[c]["before_interval"] for c in cases], color="0.6", label="before")
    for k, (role, v) in enumerate(sh.items(), start=1):
        bc = v["by_case"]
        label = f"+ {_name(v['effect'])} ({role.replace('_', '-')})"
        bar(
            k, [bc[c]["after"] for c in cases], [bc[c]["after_interval"] for c in cases], color=f"C{k - 1}", label=label
        )
    ax.axhline(100 * floor, color="tab:red", ls=":", lw=1.5, label="gap.min_gap")
    ax.set_xticks(x, cases)
    ax.set_xlabel("held-out load case")
    ax.set_ylabel("held-out gap (%)")
    ax.set_title("Per held-out case (95 % bootstrap)")


@ps.print_figure
def shrink(diag: dict, png: str, pdf: str | None = None) -> None:
    """Draw the held-out gap before and after for the winner and the runner-up, per held-out case and per harmonic.

    Parameters
    ----------
    diag
        The diagnosis (diagnosis.json; its ``shrink``).
    png
        The figure's PNG file.
    pdf
        Its PDF file, or None.
    """
    plt = ps.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(W, 3.3))
    sh = diag.get("shrink") or {}
    if not sh:
        for ax in axes:
            ax.set_axis_off()
        axes[0].text(0, 0.5, "No candidate was refitted: nothing to compare.", transform=axes[0].transAxes)
        ps.save(fig, png, pdf)
        return
    _shrink_by_case(axes[0], sh, min_gap(diag))
    v = next(iter(sh.values()))
    h = np.arange(1, len(v["by_harmonic"]["before"]) + 1)
    axes[1].semilogy(h, 100 * np.array(v["by_harmonic"]["before"]), "s--", ms=3, color="0.4", label="before")
    for k, (role, v) in enumerate(sh.items()):
        axes[1].semilogy(h, 100 * np.array(v["by_harmonic"]["after"]), "o-", ms=3, color=f"C{k}", label=role)
    ps.plain_log_ticks(axes[1].yaxis)
    axes[1].set_xticks(h)
    axes[1].set_xlabel("harmonic of the test frequency")
    axes[1].set_ylabel("residual / |A| (%)")
    axes[1].set_title("Per harmonic (held-out cases)")
    for ax in axes:
        ax.grid(alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    order = sorted(range(len(labels)), key=lambda i: labels[i] == "gap.min_gap")  # the bars first
    fig.legend([handles[i] for i in order], [labels[i] for i in order], loc="upper center", ncol=2, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.84))
    ps.save(fig, png, pdf)


WATERFALL_LABEL_WIDTH = 14  # characters per line of a waterfall bar's label (five bars fit the printed width)


def waterfall_bars(diag: dict) -> tuple[list, list, list, list]:
    """Return the waterfall's bars (labels, bottoms, heights in %, colours).

    The held-out gap the explanation starts from (the chain's identified model, before a model update that is its first
    step), what each step removes (labelled with its share of the gap's power; orange where a step widens it: an effect
    held where the random test measured it exposes one it masked, which the next step takes) and what remains.

    Parameters
    ----------
    diag
        The diagnosis (diagnosis.json: its ``explanation``, ``remaining_gap`` and ``where``).

    Returns
    -------
    labels : list
        The bars' labels.
    bottoms : list
        Where each bar starts, a held-out gap in per cent [%].
    heights : list
        Each bar's height in per cent [%] (negative where a step widens the gap).
    colors : list
        The bars' colours.
    """
    import textwrap

    steps = diag.get("explanation") or []
    left = diag.get("remaining_gap") or {}
    # the explanation's shares are of the gap it starts from: the first step's "before" (a model update's first step
    # starts from the chain's model, whose gap where.heldout_gap_identified keeps; where.heldout_gap_before is the
    # updated model's)
    before = _num(steps[0]["heldout_gap_before"]) if steps else _num(diag["where"]["heldout_gap_before"])

    def wrap(text: str) -> str:
        return textwrap.fill(text, WATERFALL_LABEL_WIDTH, break_on_hyphens=False)

    labels, bottoms, heights, colors = ["identified\nmodel"], [0.0], [100 * before], ["0.5"]
    for s in steps:
        law = " (never opens)" if never_opens(s) else " (held)" if s.get("held") else ""
        labels.append(f"{wrap('+ ' + _name(s['effect']) + law)}\n({100 * _num(s['share']):.0f} %)")
        bottoms.append(100 * _num(s["heldout_gap_after"]))
        heights.append(100 * (_num(s["heldout_gap_before"]) - _num(s["heldout_gap_after"])))
        colors.append("tab:green" if heights[-1] >= 0 else "tab:orange")
    remaining = _num(left.get("heldout_gap", before))
    labels.append("remaining\n" + wrap(f"({_name(left.get('place', diag['where'].get('place', '?')))})"))
    bottoms.append(0.0)
    heights.append(100 * remaining)
    colors.append("tab:red" if not left.get("at_floor") else "tab:blue")
    return labels, bottoms, heights, colors


@ps.print_figure
def explanation(diag: dict, png: str, pdf: str | None = None) -> None:
    """Draw the additive explanation as a waterfall (``waterfall_bars``).

    The identified model's held-out gap, what each added effect removes (its share of the gap's power), what remains;
    the identification's floor (gap.min_gap) drawn.

    Parameters
    ----------
    diag
        The diagnosis (diagnosis.json).
    png
        The figure's PNG file.
    pdf
        Its PDF file, or None.
    """
    plt = ps.pyplot()
    steps = diag.get("explanation") or []
    left = diag.get("remaining_gap") or {}
    labels, bottoms, heights, colors = waterfall_bars(diag)
    lines = max(label.count("\n") + 1 for label in labels)
    fig, ax = plt.subplots(figsize=(W, 2.5 + 0.14 * lines))
    x = np.arange(len(labels))
    ax.bar(x, heights, bottom=bottoms, color=colors, width=0.6, gid="waterfall")
    if left.get("floor") is not None:
        ax.axhline(
            100 * left["floor"],
            color="tab:red",
            ls=":",
            lw=1.5,
            label=f"gap.min_gap = {_two_digits(100 * left['floor'])} %",
        )
        fig.legend(loc="lower center", frameon=False)
    ax.set_xticks(x, labels)
    ax.set_ylabel("held-out gap (%)")
    if steps:
        title = "The held-out gap explained step by step (each step's share of its power)"
    elif left.get("at_floor"):  # nothing above what the identification itself leaves
        title = "The held-out gap is at the identification's own floor: nothing to explain"
    else:
        title = "No effect explains the held-out gap materially"
    ax.set_title(title)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout(rect=(0, 0.3 / fig.get_size_inches()[1], 1, 1))
    ps.save(fig, png, pdf)


# the views of the diagnosis; the report includes the first four (PDF), the others are results/gap/*.png only
IN_REPORT = ("stages", "ranking", "shrink", "explanation")
DIAGNOSTIC = ("harmonics", "cycle", "force_state")


def all_figures(diagnosis_path: str, gap_path: str, out: dict, thresholds: PlaceThresholds = DEFAULT_PLACE) -> None:
    """Draw every figure of the diagnosis.

    Parameters
    ----------
    diagnosis_path
        The diagnosis's diagnosis.json.
    gap_path
        The diagnosis's gap.nc.
    out
        Maps a view (``IN_REPORT``, ``DIAGNOSTIC``) to its PNG path, and ``<view>_pdf`` to its PDF where there is
        one.
    thresholds
        The localisation's thresholds (gap.place).
    """
    with open(diagnosis_path) as f:
        diag = json.load(f)
    stages(diag, out["stages"], out.get("stages_pdf"), thresholds)
    for view in IN_REPORT[1:]:
        globals()[view](diag, out[view], out.get(f"{view}_pdf"))
    with xr.open_dataset(gap_path, engine="netcdf4") as ds:
        for view in DIAGNOSTIC:
            globals()[view](ds, out[view], out.get(f"{view}_pdf"))


def failed_item_figures(reason: str, out: dict) -> None:
    """Draw, for a benchmark item the rig could not simulate, each of its figures saying why.

    Such an item has no diagnosis.

    Parameters
    ----------
    reason
        Why the item was not diagnosed.
    out
        Maps a view to its PNG path.
    """
    plt = ps.pyplot()
    for view, png in out.items():
        fig, ax = plt.subplots(figsize=(W, 1.2))
        ax.axis("off")
        ax.text(0.5, 0.5, f"not diagnosed: {reason}", ha="center", va="center", wrap=True)
        ps.save(fig, png)
