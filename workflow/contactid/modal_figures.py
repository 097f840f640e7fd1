"""The modal fit as an engineer checks it: Fig. 3 and the stability diagram of the LSCF poles.

Fig. 3 shows every sensor's FRF, measured and LSFD-synthesised, phase and coherence, the identified frequencies and
damping; the stability diagram shows the LSCF poles over model order.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from . import print_style as ps
from .frf_synthesis import synthesised_accelerance
from .linear_chain import complex_frf
from .modal_fit import StabilityPoles, stability_poles


def _band(modal: xr.Dataset) -> tuple[float, float]:
    return float(modal.attrs["band_low_hz"]), float(modal.attrs["band_high_hz"])


def _mark_band(axes, band, f_max: float) -> None:
    """Grey out the frequencies outside the fitted band on every axis."""
    for ax in axes:
        ax.axvspan(0.0, band[0], color="0.88", lw=0, zorder=0)
        ax.axvspan(
            band[1], f_max, color="0.88", lw=0, zorder=0, label="outside the fitted band" if ax is axes[0] else None
        )
        ax.set_xlim(0.0, f_max)


def _phase_deg(h: np.ndarray) -> np.ndarray:
    """Return the phase (deg) in [-180, 180] with NaN where it wraps, so that no line is drawn across the axis."""
    p = np.degrees(np.angle(h))
    p[1:][np.abs(np.diff(p)) > 180.0] = np.nan
    return p


def _mode_labels(ax, modal: xr.Dataset) -> None:
    """Write the identified natural frequencies and damping ratios at the top of the magnitude axis."""
    for fn, z in zip(modal["natural_frequency"].values, modal["damping_ratio"].values):
        ax.axvline(fn, color="0.45", lw=0.5, ls="--", zorder=1)
        ax.text(
            fn + 4.0,
            0.97,
            f"{fn:.2f} Hz\n$\\zeta$ = {100 * z:.2f} %",
            transform=ax.get_xaxis_transform(),
            va="top",
            ha="left",
            fontsize=8,
            bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 1.0},
        )


@ps.print_figure
def plot_fig03(frf: xr.Dataset, modal: xr.Dataset, png: str, pdf: str, f_max_hz: float = 500.0) -> None:
    """Draw Fig. 3: accelerance magnitude and phase of every sensor, measured and synthesised, with coherence below.

    Measured (H1) and synthesised from the identified modes (LSFD in the fitted band), with the identified frequencies
    and damping ratios written over their peaks, the frequencies outside the fitted band greyed out, and the coherence
    below.

    Parameters
    ----------
    frf
        The random test's FRF dataset (results/linear/frf.nc): ``h1_real``, ``h1_imag`` (accelerance [m/s^2/N]) and
        ``coherence`` over (``sensor``, ``frequency`` [Hz]).
    modal
        The modal fit (rule modal): ``natural_frequency`` [Hz] and ``damping_ratio`` [-] per ``mode``, the
        attributes ``band_low_hz`` and ``band_high_hz``.
    png
        Path of the PNG written.
    pdf
        Path of the PDF written.
    f_max_hz
        Upper end of the frequency axis [Hz].
    """
    plt = ps.pyplot()
    f = frf["frequency"].values
    sel = (f > 0) & (f <= f_max_hz)
    H = complex_frf(frf)
    band = _band(modal)
    in_band = (f >= band[0]) & (f <= band[1])
    fb = f[in_band]
    Hs = synthesised_accelerance(f, H, modal["natural_frequency"].values, modal["damping_ratio"].values, band)[
        :, in_band
    ]
    fig, (ax, axp, axc) = plt.subplots(
        3, 1, figsize=(ps.TEXT_WIDTH_IN, 5.6), sharex=True, gridspec_kw={"height_ratios": [3, 1.5, 1.1]}
    )
    for i, name in enumerate(frf["sensor"].values):
        ax.semilogy(f[sel], np.abs(H[i, sel]), color=f"C{i}", lw=0.9, label=f"{name} measured (H1)")
        axp.plot(f[sel], _phase_deg(H[i, sel]), color=f"C{i}", lw=0.7)
        axc.plot(f[sel], frf["coherence"].values[i, sel], color=f"C{i}", lw=0.8)
    for i in range(H.shape[0]):
        kw = {"color": "k", "ls": (0, (3, 2)), "lw": 0.7}
        ax.semilogy(fb, np.abs(Hs[i]), label="LSFD synthesis" if i == 0 else None, **kw)
        axp.plot(fb, _phase_deg(Hs[i]), **kw)
    _mark_band((ax, axp, axc), band, f_max_hz)
    _mode_labels(ax, modal)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi * 30)  # room for the mode labels above the peaks
    ps.plain_log_ticks(ax.yaxis)
    ax.set_ylabel("|accelerance| (m s⁻²/N)")
    ax.legend(loc="lower right", ncol=3)
    axp.set_ylim(-180, 180)
    axp.set_yticks([-180, -90, 0, 90, 180])
    axp.set_ylabel("phase (deg)")
    axc.set_ylim(0, 1.05)
    axc.set_ylabel("coherence (-)")
    axc.set_xlabel("frequency (Hz)")
    for a in (ax, axp, axc):
        a.grid(True, which="major", alpha=0.3)
    fig.align_ylabels((ax, axp, axc))
    fig.tight_layout(h_pad=0.4)
    ps.save(fig, png, pdf)


# category of a pole: (mask on StabilityPoles, marker, colour, size, label)
def _categories(sp: StabilityPoles):
    f, d, v = sp.stable_frequency, sp.stable_damping, sp.stable_vector
    return (
        (~f, ".", "0.55", 3, "new or unstable"),
        (f & ~d & ~v, "^", "C1", 4, "stable frequency"),
        (f & d & ~v, "s", "C2", 4, "stable frequency, damping"),
        (f & ~d & v, "D", "C4", 4, "stable frequency, vector"),
        (f & d & v, "o", "C0", 4, "stable frequency, damping, vector"),
    )


def consecutive_stable_orders(sp: StabilityPoles, frequency_hz: float, order: int, tol: float = 0.01) -> int:
    """Return how many consecutive orders up to ``order`` have a fully stable pole near ``frequency_hz``.

    A pole within ``tol`` (relative) of ``frequency_hz`` that is stable in frequency, damping and vector; counted down
    from ``order`` until an order has none.

    Parameters
    ----------
    sp
        The stability diagram's poles.
    frequency_hz
        The mode's frequency [Hz].
    order
        The highest model order counted.
    tol
        Relative frequency tolerance [-].

    Returns
    -------
    int
        The number of consecutive orders, 0 where ``order`` itself has no such pole.
    """
    n = 0
    for o in range(order, int(sp.order.min()) - 1, -1):
        here = (sp.order == o) & sp.stable & (np.abs(sp.frequency_hz / frequency_hz - 1) <= tol)
        if not here.any():
            break
        n += 1
    return n


@ps.print_figure
def plot_stability(frf: xr.Dataset, modal: xr.Dataset, png: str, pdf: str, min_order: int = 2) -> StabilityPoles:
    """Draw the stability diagram of the LSCF poles in the fitted band and return the poles.

    The poles at orders ``min_order``..modal order (marked by how they compare with the previous order), the chosen
    poles (the identified modes) ringed, over the summed accelerance magnitude of all sensors (right axis).

    Parameters
    ----------
    frf
        The random test's FRF dataset (results/linear/frf.nc): ``h1_real``, ``h1_imag`` (accelerance [m/s^2/N]) over
        (``sensor``, ``frequency`` [Hz]).
    modal
        The modal fit (rule modal): ``natural_frequency`` [Hz] per ``mode``, the attributes ``band_low_hz``,
        ``band_high_hz`` and ``order`` (the model order of the chosen poles).
    png
        Path of the PNG written.
    pdf
        Path of the PDF written.
    min_order
        The lowest model order drawn.

    Returns
    -------
    poles : StabilityPoles
        The poles of every order drawn.
    """
    plt = ps.pyplot()
    band, order = _band(modal), int(modal.attrs["order"])
    f, H = frf["frequency"].values, complex_frf(frf)
    sp = stability_poles(f, H, band, range(min_order, order + 1))
    fig, ax = plt.subplots(figsize=(ps.TEXT_WIDTH_IN, 3.9))
    axh = ax.twinx()
    sel = (f >= band[0]) & (f <= band[1])
    axh.semilogy(f[sel], np.abs(H[:, sel]).sum(axis=0), color="0.6", lw=0.7, label="summed |H| (right axis)")
    ps.plain_log_ticks(axh.yaxis)
    axh.set_ylabel("summed |accelerance| (m s⁻²/N)")
    ax.set_zorder(axh.get_zorder() + 1)
    ax.patch.set_visible(False)
    for mask, marker, colour, size, label in _categories(sp):
        ax.plot(
            sp.frequency_hz[mask], sp.order[mask], marker, color=colour, ms=size, mfc=colour, ls="none", label=label
        )
    ax.plot(
        modal["natural_frequency"].values,
        np.full(modal.sizes["mode"], order),
        "o",
        ms=10,
        mfc="none",
        mec="C3",
        mew=1.4,
        ls="none",
        label="chosen poles (identified modes)",
    )
    ax.set_xlim(*band)
    ax.set_ylim(min_order - 0.7, order + 0.7)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("LSCF model order")
    ax.grid(alpha=0.3)
    handles = ax.get_legend_handles_labels()
    extra = axh.get_legend_handles_labels()
    fig.legend(handles[0] + extra[0], handles[1] + extra[1], loc="upper center", ncol=3, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.85))
    ps.save(fig, png, pdf)
    return sp
