"""Monte Carlo study of identification accuracy against sensor noise and record length.

Each point of the parameter table (noise fraction, dual-sine record length, seed) is one small,
independent job: the virtual rig records a random test and the calibration case at that noise and
length, the chain identifies k_t and the friction law from them in one process (the same package
functions as the rules, ``gap.pipeline.identify``), and the errors against the rig's truth are
returned. The gathering step stacks the points into a dataset and draws the errors against noise.
"""

from __future__ import annotations

import itertools
import time
from typing import Any, Mapping

import numpy as np
import pandas as pd
import xarray as xr

from . import print_style as ps
from .contact_laws import stiction_shear_stiffness

QUANTITIES = ("mu", "e0", "k_t")


def noise_study_table(study_cfg: Mapping[str, Any] | None) -> pd.DataFrame:
    """Return the noise study's parameter table: one row per (noise_fraction, record_samples, seed), in that order.

    Every combination of the configured axes; an axis the config leaves out takes the schema's default.

    Parameters
    ----------
    study_cfg
        The config's ``noise_study`` mapping (``noise_fractions``, ``record_samples``, ``seeds``; ``in_report`` is
        not read), or None for the schema's defaults.

    Returns
    -------
    table : pd.DataFrame
        Columns ``noise_fraction`` (sensor noise rms over signal rms), ``record_samples`` and ``seed``.

    Raises
    ------
    ValueError
        When an axis is empty, a noise fraction is negative or a record is shorter than 1024 samples.
    """
    from .schema import schema_defaults

    axes = {k: v for k, v in schema_defaults("noise_study").items() if k != "in_report"}  # the schema's defaults
    c = {**axes, **{k: v for k, v in dict(study_cfg or {}).items() if k in axes}}
    for key in axes:
        if not c[key]:
            raise ValueError(f"noise_study.{key} is empty; give at least one value")
    if min(c["noise_fractions"]) < 0:
        raise ValueError(f"noise_study.noise_fractions = {c['noise_fractions']}: noise fractions are >= 0")
    if min(c["record_samples"]) < 1024:
        raise ValueError(f"noise_study.record_samples = {c['record_samples']}: give at least 1024 samples per record")
    rows = [
        {"noise_fraction": float(n), "record_samples": int(r), "seed": int(s)}
        for n, r, s in itertools.product(c["noise_fractions"], c["record_samples"], c["seeds"])
    ]
    return pd.DataFrame(rows, columns=["noise_fraction", "record_samples", "seed"])


def e0_at(e_f: float, k_c: float, normal_force: float) -> float:
    """Return the tangential stiffness e_0 of the modified Valanis law at a normal force.

    e_0 = e_f (1 - exp(-k_c N / e_f)) (Eq. 22).

    Parameters
    ----------
    e_f
        The law's e_f [N/m].
    k_c
        The law's k_c [1/m].
    normal_force
        Total normal force N [N], compression positive.

    Returns
    -------
    e0 : float
        Tangential stiffness at stiction [N/m].
    """
    return float(stiction_shear_stiffness(normal_force, e_f, k_c))


def run_point(cfg: Mapping[str, Any], noise_fraction: float, record_samples: int, seed: int) -> dict:
    """Run one point of the noise study: rig records, the identification and its errors against the rig's truth.

    The virtual rig records a random test and the calibration case at this noise and length (rig seed = config seed +
    ``seed``, no rig effects), the chain identifies k_t and the friction law from them (``gap.pipeline.identify``), and
    the relative errors of mu, e_0 (at the preload) and k_t against the rig's truth are returned.

    Parameters
    ----------
    cfg
        The whole config (a copy at the schema's defaults is used; reads ``seed``, ``rig``, ``random_test``,
        ``structure``, ``load_cases`` and ``nonlinear.calibration_case``).
    noise_fraction
        Sensor noise, rms over signal rms [-].
    record_samples
        Length of the dual-sine record, in samples.
    seed
        Seed offset of the point's rig records.

    Returns
    -------
    point : dict
        ``noise_fraction``, ``record_samples``, ``seed``; the identified ``mu`` [-], ``e0`` [N/m] and ``k_t`` [N/m]
        with their truths (``*_true``) and relative errors (``error_*``, identified / truth - 1); ``seconds``: the wall
        times [s] of the rig (``rig``) and of the identification (``identification``).
    """
    from .gap.pipeline import identify
    from .rig.dual_sine import dual_sine_test
    from .rig.random_test import random_test_datasets
    from .rig.structure import random_test_rig_config
    from .schema import with_defaults

    t0 = time.perf_counter()
    cfg = with_defaults(cfg)  # a copy, at the schema's defaults where keys are left out
    rig = cfg["rig"]
    rig["noise_fraction"] = float(noise_fraction)
    rig.setdefault("dual_sine", {})["record_samples"] = int(record_samples)
    rig["effects"] = {}
    rig_seed = int(cfg["seed"]) + int(seed)
    cal = cfg["nonlinear"]["calibration_case"]
    raw_rt, truth_rt = random_test_datasets(cfg["structure"], random_test_rig_config(rig), cfg["random_test"], rig_seed)
    fs = float(cfg["random_test"]["sampling_rate_hz"])
    raw_cal, truth_cal = dual_sine_test(
        cfg["structure"],
        rig,
        cfg["load_cases"][cal],
        fs,
        float(noise_fraction),
        rig_seed,
        cal,
        cfg["structure"]["sensors"]["names"],
    )
    t_rig = time.perf_counter() - t0
    model, modes, _, _ = identify(cfg, raw_rt, raw_cal)
    tf = rig["truth"]["friction"]
    N0 = float(truth_cal.attrs["preload_n"])
    e_f, k_c, _, _, mu = (float(x) for x in model.friction)
    e0, e0_true = e0_at(e_f, k_c, N0), e0_at(tf["e_f_n_per_m"], tf["k_c_per_m"], N0)
    k_t, k_t_true = float(modes["k_t"]), float(truth_rt["k_t"])
    return {
        "noise_fraction": float(noise_fraction),
        "record_samples": int(record_samples),
        "seed": int(seed),
        "mu": mu,
        "mu_true": float(tf["mu"]),
        "e0": e0,
        "e0_true": e0_true,
        "k_t": k_t,
        "k_t_true": k_t_true,
        "error_mu": mu / float(tf["mu"]) - 1.0,
        "error_e0": e0 / e0_true - 1.0,
        "error_k_t": k_t / k_t_true - 1.0,
        "seconds": {"rig": t_rig, "identification": time.perf_counter() - t0 - t_rig},
    }


def gather(rows: list[dict]) -> xr.Dataset:
    """Stack the noise study's points on (noise_fraction, record_samples, seed).

    Parameters
    ----------
    rows
        The points, as ``run_point`` returns them.

    Returns
    -------
    study : xr.Dataset
        Identified values, truths and relative errors of mu, e_0 and k_t (``mu``, ``mu_true``, ``error_mu``, ...,
        with units), and ``seconds``, each point's total wall time [s].
    """
    df = pd.DataFrame(
        [{**{k: v for k, v in r.items() if k != "seconds"}, "seconds": sum(r["seconds"].values())} for r in rows]
    )
    df = df.set_index(["noise_fraction", "record_samples", "seed"]).sort_index()
    ds = xr.Dataset.from_dataframe(df)
    meaning = {
        "mu": ("1", "friction coefficient mu"),
        "e0": ("N/m", "tangential stiffness e_0 at the preload (Eq. 22)"),
        "k_t": ("N/m", "contact stiffness at stiction k_t"),
    }
    for q, (unit, name) in meaning.items():
        ds[q].attrs.update(units=unit, long_name=f"identified {name}")
        ds[f"{q}_true"].attrs.update(units=unit, long_name=f"rig truth: {name}")
        ds[f"error_{q}"].attrs.update(units="1", long_name=f"relative error of {name} (identified / truth - 1)")
    ds["noise_fraction"].attrs.update(units="1", long_name="sensor noise rms over signal rms")
    ds["record_samples"].attrs.update(units="1", long_name="dual-sine record length (samples)")
    ds["seed"].attrs.update(units="1", long_name="seed offset of the point's rig records")
    ds["seconds"].attrs.update(units="s", long_name="wall time of the point's job")
    return ds


@ps.print_figure
def plot_noise_study(ds: xr.Dataset, default_noise: float, png: str, pdf: str | None = None) -> None:
    """Draw |error| of mu, e_0 and k_t against the noise fraction.

    Every seed as a dot, the median as a line per record length; the default noise marked. Drawn at the report's text
    width (print_style).

    Parameters
    ----------
    ds
        The study (``gather``).
    default_noise
        The configured sensor noise, marked on the axes (rms over signal rms) [-].
    png
        Path of the PNG written.
    pdf
        Path of the PDF written; None: no PDF.
    """
    import matplotlib.ticker

    plt = ps.pyplot()
    noise = ds["noise_fraction"].values
    fig, axes = plt.subplots(1, len(QUANTITIES), figsize=(ps.TEXT_WIDTH_IN, 3.0), sharex=True)
    labels = {"mu": r"$\mu$", "e0": "e₀ at N₀", "k_t": "kₜ"}
    for ax, q in zip(axes, QUANTITIES):
        err = 100 * np.abs(ds[f"error_{q}"].values)  # (noise, length, seed)
        for j, n in enumerate(ds["record_samples"].values):
            (line,) = ax.plot(noise, np.median(err[:, j, :], axis=1), "-o", ms=3, label=f"{int(n)} samples")
            for s in range(err.shape[2]):
                ax.plot(noise, err[:, j, s], ".", color=line.get_color(), alpha=0.4)
        ax.axvline(default_noise, color="k", ls="--", lw=0.8)
        ax.text(default_noise, 0.97, " default", transform=ax.get_xaxis_transform(), va="top", fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ps.plain_log_ticks(ax.yaxis)
        ax.set_xticks(noise)
        ax.set_xticklabels([f"{x:g}" for x in noise], rotation=45, fontsize=8)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("sensor noise (rms fraction)")
        ax.set_title(f"|error| of {labels[q]} (%)")
    axes[0].legend(fontsize=8)
    axes[-1].text(
        0.97,
        0.03,
        "from the random test:\nthe same for every\nrecord length",
        transform=axes[-1].transAxes,
        ha="right",
        fontsize=8,
        bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 1.0},
    )
    fig.tight_layout(w_pad=0.5)
    ps.save(fig, png, pdf)


def report_section(ds: xr.Dataset | None) -> str:
    """Return the report's section on the noise study.

    Medians over seeds at the default noise and at the largest, and the figure; without the study
    (noise_study.in_report: false) a sentence saying how to run it.

    Parameters
    ----------
    ds
        The study (``gather``; the attribute ``default_noise_fraction`` marks the default noise), or None.

    Returns
    -------
    section : str
        The section, in LaTeX.
    """
    head = "\\section{Identification accuracy against sensor noise and record length}\n"
    if ds is None:
        return head + (
            "The Monte Carlo study is not part of this report (\\texttt{noise\\_study.in\\_report: false}); "
            "\\texttt{snakemake noise\\_study} runs it.\n"
        )
    noise = ds["noise_fraction"].values
    longest = int(ds["record_samples"].values.max())
    default = float(ds.attrs.get("default_noise_fraction", noise[len(noise) // 2]))
    i_def = int(np.argmin(np.abs(noise - default)))

    def med(q, i):
        return 100 * float(np.median(np.abs(ds[f"error_{q}"].sel(record_samples=longest).values[i])))

    n_points = ds.sizes["noise_fraction"] * ds.sizes["record_samples"] * ds.sizes["seed"]
    text = (
        f"Each of the {n_points} points of the parameter table (noise fractions "
        f"{', '.join(f'{x:g}' for x in noise)}; records of "
        f"{', '.join(str(int(r)) for r in ds['record_samples'].values)} "
        f"samples; {ds.sizes['seed']} seeds) is one Snakemake job: the rig records a random test and the calibration "
        f"case, the chain identifies $k_t$ and the friction law, and the errors against the rig's truth are gathered "
        f"(Fig.~\\ref{{fig:noise}}). With {longest}-sample records the median error of $\\mu$ is "
        f"{med('mu', i_def):.2g}\\,\\% at the default noise ({noise[i_def]:g}) and {med('mu', -1):.2g}\\,\\% at "
        f"{noise[-1]:g}; of $e_0$ {med('e0', i_def):.2g}\\,\\% and {med('e0', -1):.2g}\\,\\%; of $k_t$ "
        f"{med('k_t', i_def):.2g}\\,\\% and {med('k_t', -1):.2g}\\,\\%.\n"
    )
    fig = (
        "\\begin{figure}[H]\\centering\\includegraphics[width=\\textwidth]{noise_study.pdf}\n"
        "\\caption{Relative error of $\\mu$, $e_0$ at the preload and $k_t$ against the sensor noise: dots are seeds, "
        "lines the medians per dual-sine record length ($k_t$ comes from the random test, the same for both); the "
        "dashed line marks the default noise.}\\label{fig:noise}\\end{figure}\n"
    )
    return head + text + fig
