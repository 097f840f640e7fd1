"""Figs. 4-9 of the paper and the GA convergence.

Drawn at the width paper/report.tex prints them at (:mod:`contactid.print_style`): text at least 8 pt on paper.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr

from . import print_style as ps
from .consistency import TABLE4
from .contact_laws import stiction_shear_stiffness
from .friction_parameters import fitted_parameters


def _periods(t: np.ndarray, f0: float, periods: int = 3, last: bool = False):
    """Return the samples (a mask of ``t``, s) of the record's first ``periods`` periods of ``f0`` (Hz), or its last."""
    return t >= t[-1] - periods / f0 if last else t <= periods / f0


@ps.print_figure
def plot_fig04(gc: xr.Dataset, case: str, png: str, pdf: str) -> None:
    """Draw Fig. 4: generalized coordinates p_i(t) of the linear modes (Eq. 17), three periods.

    Parameters
    ----------
    gc
        The load case's generalized coordinates (rule generalized_coordinates): ``p`` [kg^0.5 m] over (``mode``,
        ``time`` [s]), the attribute ``excitation_frequency_hz``.
    case
        The load case's name (in the title).
    png
        Path of the PNG written.
    pdf
        Path of the PDF written.
    """
    plt = ps.pyplot()
    t = gc["time"].values
    sel = _periods(t, gc.attrs["excitation_frequency_hz"])
    fig, ax = plt.subplots(figsize=(ps.NARROW_WIDTH_IN, 2.9))
    for i, m in enumerate(gc["mode"].values):
        ax.plot(1e3 * t[sel], 1e3 * gc["p"].values[i, sel], lw=1.0, label=f"p{ps.sub(m)}")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("pᵢ (10⁻³ kg¹ᐟ² m)")
    ax.set_title(f"Generalized coordinates of the linear modes, {case}")
    ax.legend(ncol=3, loc="upper right")
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.3 * (hi - lo))  # room for the legend above the signals
    ax.grid(alpha=0.3)
    fig.tight_layout()
    ps.save(fig, png, pdf)


@ps.print_figure
def plot_fig05(nnm: xr.Dataset, case: str, png: str, pdf: str) -> None:
    """Draw Fig. 5: driving-point acceleration, measured (line) and reconstructed from the NNMs (circles).

    Over the record's first three periods.

    Parameters
    ----------
    nnm
        The load case's nonlinear normal modes (rule nonlinear_modes): ``drive_measured`` and ``drive_reconstructed``
        [m/s^2] over ``time`` [s], the attributes ``excitation_frequency_hz`` and ``reconstruction_nrmse`` (a fraction).
    case
        The load case's name (in the title).
    png
        Path of the PNG written.
    pdf
        Path of the PDF written.
    """
    plt = ps.pyplot()
    t = nnm["time"].values
    sel = slice(0, int(np.searchsorted(t, 3.0 / nnm.attrs["excitation_frequency_hz"])))
    fig, ax = plt.subplots(figsize=(ps.NARROW_WIDTH_IN, 2.9))
    ax.plot(1e3 * t[sel], nnm["drive_measured"].values[sel], "-", lw=1.0, color="C0", label="measured")
    ax.plot(
        1e3 * t[sel],
        nnm["drive_reconstructed"].values[sel],
        "o",
        ms=2.5,
        mfc="none",
        mew=0.6,
        color="C3",
        label=f"from the NNMs (NRMSE {100 * nnm.attrs['reconstruction_nrmse']:.1f} %)",
    )
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("acceleration at dₚ (m s⁻²)")
    ax.set_title(f"Driving-point acceleration, {case}")
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.35 * (hi - lo))  # room for the legend above the signal
    ax.legend(loc="upper right", ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    ps.save(fig, png, pdf)


# Fig. 6's loops: force, motion, x label, y label
_LOOPS = (("S", "xi", r"$\xi$ ($\mu$m)", "S (N)"), ("N_dyn", "eta", r"$\eta$ ($\mu$m)", "N − N₀ (N)"))


def _limits(values: np.ndarray, pad: float = 0.08) -> tuple[float, float]:
    """Return axis limits around ``values`` with ``pad`` of their span on each side (never a zero span)."""
    lo, hi = float(np.nanmin(values)), float(np.nanmax(values))
    span = hi - lo if hi > lo else max(abs(hi), 1e-12)
    return lo - pad * span, hi + pad * span


LOOP_PERIODS = 4  # Fig. 6 draws each loop over the record's last periods


def _last_periods(ds: xr.Dataset, periods: int = LOOP_PERIODS):
    """Return the samples of the record's last ``periods`` periods.

    Periods of its ``excitation_frequency_hz``; every sample where the dataset does not say. The identified loops
    repeat every period (harmonic series) and the rig's settle: drawn over a whole record, 170 periods on top of each
    other gave the same picture as a 2 MB PDF that took 10 s.
    """
    f0 = ds.attrs.get("excitation_frequency_hz")
    if not f0 or "time" not in ds.coords:
        return slice(None)
    return _periods(ds["time"].values, float(f0), periods, last=True)


def _loop_panel(ax, ds: xr.Dataset, force: str, motion: str, suffix: str, colour: str, label: str) -> None:
    """Draw one hysteresis loop over the truth where there is one; the axis limits are the loop's own.

    ``force`` + ``suffix`` against ``motion`` + ``suffix``, over the record's last ``LOOP_PERIODS`` periods.
    """
    sel = _last_periods(ds)
    x, y = 1e6 * ds[motion + suffix].values[sel], ds[force + suffix].values[sel]
    if f"{force}_truth" in ds:
        ax.plot(
            1e6 * ds[f"{motion}_truth"].values[sel],
            ds[f"{force}_truth"].values[sel],
            color="0.7",
            lw=2.6,
            label="rig truth",
        )
    ax.plot(x, y, "-", color=colour, lw=1.0, label=label)
    ax.set_xlim(*_limits(x))
    ax.set_ylim(*_limits(y))
    ax.grid(alpha=0.3)


@ps.print_figure
def plot_fig06(forces: Mapping[str, xr.Dataset], png: str, pdf: str) -> None:
    """Draw Fig. 6: S-xi and N-eta loops per load case (the record's last ``LOOP_PERIODS`` periods).

    The working method (the correction) over the rig truth where it exists, limits from the working method; the
    paper's chain (the reproduction) in rows of its own, on its own scale; one legend for every panel.

    Parameters
    ----------
    forces
        Load case -> its identified contact forces (rule contact_forces): ``S`` [N], ``xi`` [m], ``N_dyn`` [N] and
        ``eta`` [m] over ``time`` [s], the same with the suffix ``_paper`` (the paper's chain) and, from the rig,
        ``_truth``; the attribute ``excitation_frequency_hz``.
    png
        Path of the PNG written.
    pdf
        Path of the PDF written.
    """
    plt = ps.pyplot()
    cases = list(forces)
    fig, axes = plt.subplots(4, len(cases), figsize=(ps.TEXT_WIDTH_IN, 8.2), squeeze=False)
    for j, case in enumerate(cases):
        for row, (force, motion, xl, yl) in enumerate(_LOOPS):
            for k, (suffix, colour, who) in enumerate(
                (("", "C0", "working method"), ("_paper", "C3", "paper's chain"))
            ):
                ax = axes[row + 2 * k, j]
                _loop_panel(ax, forces[case], force, motion, suffix, colour, who)
                ax.set_xlabel(xl, labelpad=1)
                if j == 0:
                    ax.set_ylabel(yl)
                ax.set_title(f"{case}, {who}", fontsize=8.5)
    handles = {}
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(handles.values(), handles.keys(), loc="upper center", ncol=len(handles), frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.975), h_pad=0.6, w_pad=0.6)
    ps.save(fig, png, pdf)


def _fig07(fit: xr.Dataset, validations: Mapping[str, xr.Dataset], truth_friction: Mapping | None, png, pdf) -> None:
    """Draw Fig. 7: e_0 against N: identified, the paper's Table 4, the truth, and each load case's range of N."""
    plt = ps.pyplot()
    n0 = fit.attrs["preload_n"]
    N = np.linspace(0, 2.5 * n0, 200)
    p = dict(zip(fit["parameter"].values, fitted_parameters(fit)))
    fig, ax = plt.subplots(figsize=(ps.NARROW_WIDTH_IN, 3.0))
    ax.plot(N, 1e-6 * stiction_shear_stiffness(N, p["e_f"], p["k_c"]), "-", color="C0", label="identified")
    ax.plot(
        N, 1e-6 * stiction_shear_stiffness(N, TABLE4["e_f"], TABLE4["k_c"]), "--", color="C1", label="paper, Table 4"
    )
    if truth_friction:
        ef, kc = float(truth_friction["e_f_n_per_m"]), float(truth_friction["k_c_per_m"])
        ax.plot(N, 1e-6 * stiction_shear_stiffness(N, ef, kc), ":", color="0.3", lw=2, label="rig truth")
    for k, (case, v) in enumerate(validations.items()):
        ax.axvspan(v["N"].values.min(), v["N"].values.max(), color=f"C{k + 2}", alpha=0.15, label=f"N range, {case}")
    ax.set_xlabel("normal force N (N)")
    ax.set_ylabel("e₀ (10⁶ N/m)")
    ax.set_title("Contact shear stiffness at stiction, Eq. 22")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    ps.save(fig, png, pdf)


def _fig08_09(validations: Mapping[str, xr.Dataset], xvar: str, xlabel: str, scale: float, png, pdf) -> None:
    """Draw Figs. 8 and 9: S identified (circles) and predicted by the fitted law (line) against ``xvar``."""
    plt = ps.pyplot()
    cases = list(validations)
    fig, axes = plt.subplots(1, len(cases), figsize=(ps.TEXT_WIDTH_IN, 2.6), squeeze=False)
    for j, case in enumerate(cases):
        v = validations[case]
        ax = axes[0, j]
        x = scale * v[xvar].values
        ax.plot(x[::4], v["S_identified"].values[::4], "o", ms=2.5, mfc="none", mew=0.6, color="C0", label="identified")
        ax.plot(x, v["S_predicted"].values, "-", color="C3", lw=1.0, label="predicted")
        ax.set_title(f"{case} (NRMSE {100 * v.attrs['nrmse_vs_identified']:.1f} %)", fontsize=8.5)
        ax.set_xlabel(xlabel)
        if j == 0:
            ax.set_ylabel("S (N)")
        ax.grid(alpha=0.3)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=2, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.92), w_pad=0.6)
    ps.save(fig, png, pdf)


def _convergence(fit: xr.Dataset, png: str) -> None:
    """Draw the genetic algorithm's best and mean misfit per generation and the misfit after the polish."""
    plt = ps.pyplot()
    fig, ax = plt.subplots(figsize=(ps.NARROW_WIDTH_IN, 2.8))
    ax.semilogy(fit["generation"].values, fit["ga_best"].values, label="best")
    ax.semilogy(fit["generation"].values, fit["ga_mean"].values, label="mean")
    ps.plain_log_ticks(ax.yaxis)
    ax.axhline(fit.attrs["misfit_nrmse"], color="0.4", ls="--", label="after polish")
    ax.set_xlabel("generation")
    ax.set_ylabel("misfit (NRMSE of S)")
    ax.set_title("Genetic algorithm convergence")
    ax.legend()
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    ps.save(fig, png)


@ps.print_figure
def plot_friction_figures(
    fit: xr.Dataset,
    validations: Mapping[str, xr.Dataset],
    truth_friction: Mapping[str, Any] | None,
    paths: Mapping[str, str],
) -> None:
    """Draw Fig. 7 (e_0 vs N), Fig. 8 (S vs xi), Fig. 9 (S vs xi'), and the GA convergence.

    Parameters
    ----------
    fit
        The friction fit's dataset (``friction_datasets.friction_fit_dataset``): the law's parameters, ``ga_best``
        and ``ga_mean`` per ``generation``, the attributes ``preload_n`` and ``misfit_nrmse``.
    validations
        Load case -> its validation dataset (``friction_datasets.validation_dataset``): ``xi`` [m], ``xi_dot``
        [m/s], ``N`` [N], ``S_identified`` and ``S_predicted`` [N] over one period, the attribute
        ``nrmse_vs_identified``.
    truth_friction
        The rig truth's friction law (``e_f_n_per_m``, ``k_c_per_m``, ...), or None (measured records: no truth
        drawn).
    paths
        Output paths by name: ``fig07_png``, ``fig07_pdf``, ``fig08_png``, ``fig08_pdf``, ``fig09_png``,
        ``fig09_pdf`` and ``convergence_png``.
    """
    _fig07(fit, validations, truth_friction, paths["fig07_png"], paths["fig07_pdf"])
    _fig08_09(validations, "xi", r"$\xi$ ($\mu$m)", 1e6, paths["fig08_png"], paths["fig08_pdf"])
    _fig08_09(validations, "xi_dot", r"d$\xi$/dt (mm/s)", 1e3, paths["fig09_png"], paths["fig09_pdf"])
    _convergence(fit, paths["convergence_png"])
