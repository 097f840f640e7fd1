"""The linear chain's datasets: FRF -> modal fit -> stiction stiffness -> linear modes.

Each function takes the previous step's dataset (and config values) and returns
the next step's dataset, so the rule scripts stay a few lines long.
"""

from __future__ import annotations

import logging
from typing import Collection, Mapping, Sequence

import numpy as np
import xarray as xr

from .beam_model import assemble, shape_on_grid
from .beam_modes import structural_modes
from .io import RawDataError
from .modal_fit import fit_modes
from .parameters import identified_structure, structure_from_config
from .signals import h1_frf
from .stiction import frequency_sigma, stiction_stiffness

log = logging.getLogger(__name__)


def check_sensor_layout(raw: xr.Dataset, structure_cfg: Mapping, path: str, tol_m: float = 1e-3) -> None:
    """Check that the raw record's sensor positions are those of the structure model.

    Parameters
    ----------
    raw
        The raw record: reads its coordinate ``position`` (sensor) [m].
    structure_cfg
        The config's ``structure`` block: reads ``sensors.positions_m`` [m].
    path
        The record's path, for the message.
    tol_m
        How far a position may lie from the model's [m].

    Raises
    ------
    RawDataError
        When the record has another number of sensors or a sensor lies more than ``tol_m`` from the model's.
    """
    pos = np.asarray(raw["position"].values, dtype=float)
    want = np.asarray(structure_cfg["sensors"]["positions_m"], dtype=float)
    if pos.shape != want.shape or np.max(np.abs(pos - want)) > tol_m:
        raise RawDataError(
            f"{path}: sensor positions {pos.tolist()} m differ from structure.sensors.positions_m "
            f"{want.tolist()} m; make the model's sensor layout (config) match the test"
        )


def frf_dataset(raw: xr.Dataset, segment_length: int, overlap: float, window: str, blocks: int) -> xr.Dataset:
    """Return H1 and coherence of every accelerometer over the force, for the record and for sub-records.

    H1 and coherence are those of the whole record, plus H1 of ``blocks`` consecutive sub-records (for the modal
    fit's statistical uncertainty), interpolated onto the whole record's frequencies; a sub-record shorter than two
    segments is analysed with segments of half its length.

    Parameters
    ----------
    raw
        The random test's raw record: ``force`` (time) [N], ``acceleration`` (sensor, time) [m/s^2], the coordinates
        ``sensor`` and ``position`` [m], the attribute ``sampling_rate_hz`` [Hz].
    segment_length
        Welch segment length [samples] (config ``frf.segment_length``).
    overlap
        Overlap of consecutive segments, a fraction of the segment length [-] (``frf.overlap``).
    window
        The segments' window, a scipy.signal window name (``frf.window``).
    blocks
        Number of consecutive sub-records (``modal.uncertainty_blocks``).

    Returns
    -------
    frf : xr.Dataset
        The FRF dataset (results/linear/frf.nc) of ``frf_result_dataset``, its attributes the averages, the
        settings, the sampling rate and the driving-point sensor (the first).

    Raises
    ------
    RawDataError
        When the record is shorter than two segments.
    """
    fs = float(raw.attrs["sampling_rate_hz"])
    force = raw["force"].values
    acc = raw["acceleration"].values
    n = force.size
    if n < 2 * segment_length:
        raise RawDataError(
            f"record of {n} samples is shorter than two FRF segments of {segment_length}; "
            "lengthen the record or lower frf.segment_length"
        )
    full = h1_frf(force, acc, fs, segment_length, overlap, window)
    nb = n // blocks
    block_h1 = []
    seg_b = segment_length if nb >= 2 * segment_length else nb // 2
    for b in range(blocks):
        sl = slice(b * nb, (b + 1) * nb)
        est = h1_frf(force[sl], acc[:, sl], fs, seg_b, overlap, window)
        block_h1.append(
            np.stack(
                [
                    np.interp(full.frequency_hz, est.frequency_hz, h.real)
                    + 1j * np.interp(full.frequency_hz, est.frequency_hz, h.imag)
                    for h in est.h1
                ]
            )
        )
    attrs = {
        "n_averages": full.n_averages,
        "segment_length": segment_length,
        "overlap": overlap,
        "window": window,
        "sampling_rate_hz": fs,
        "driving_point_sensor": str(raw["sensor"].values[0]),
    }
    return frf_result_dataset(
        full.frequency_hz,
        full.h1,
        full.coherence,
        np.array(block_h1),
        raw["sensor"].values,
        raw["position"].values,
        attrs,
    )


def frf_result_dataset(
    frequency_hz: np.ndarray,
    h1: np.ndarray,
    coherence: np.ndarray,
    block_h1: np.ndarray,
    sensors: Collection[str],
    positions_m: np.ndarray | Sequence[float],
    attrs: Mapping,
) -> xr.Dataset:
    """Return the FRF dataset (results/linear/frf.nc) the modal fit reads.

    The dataset holds H1 accelerance (sensor, frequency) as real and imaginary parts in m/s^2/N, the ordinary
    coherence (1), H1 of sub-records (block, sensor, frequency; the block dimension may be empty: no sub-records),
    frequency (Hz), sensor names and positions (m), and ``attrs``. One home of the variables, units and names, for
    the FRF from a time record and the FRF imported from a file.

    Parameters
    ----------
    frequency_hz
        Frequency lines [Hz], shape (n_f,).
    h1
        Complex H1 accelerance of each sensor over the force [m/s^2/N], shape (n_sensors, n_f).
    coherence
        Ordinary coherence of each sensor with the force [-], shape (n_sensors, n_f).
    block_h1
        Complex H1 of the consecutive sub-records [m/s^2/N], shape (n_blocks, n_sensors, n_f); n_blocks may be 0.
    sensors
        The sensors' names, n_sensors of them.
    positions_m
        The sensors' distances from the clamp [m], shape (n_sensors,).
    attrs
        The dataset's attributes (copied).

    Returns
    -------
    frf : xr.Dataset
        The FRF dataset.
    """
    block_h1 = np.asarray(block_h1, dtype=complex).reshape(-1, *np.shape(h1))
    return xr.Dataset(
        {
            "h1_real": (
                ("sensor", "frequency"),
                np.real(h1),
                {"units": "m/s^2/N", "long_name": "H1 accelerance, real part"},
            ),
            "h1_imag": (
                ("sensor", "frequency"),
                np.imag(h1),
                {"units": "m/s^2/N", "long_name": "H1 accelerance, imaginary part"},
            ),
            "coherence": (("sensor", "frequency"), coherence, {"units": "1", "long_name": "ordinary coherence"}),
            "block_h1_real": (
                ("block", "sensor", "frequency"),
                block_h1.real,
                {"units": "m/s^2/N", "long_name": "H1 of consecutive sub-records, real part"},
            ),
            "block_h1_imag": (
                ("block", "sensor", "frequency"),
                block_h1.imag,
                {"units": "m/s^2/N", "long_name": "H1 of consecutive sub-records, imaginary part"},
            ),
        },
        coords={
            "frequency": (
                "frequency",
                np.asarray(frequency_hz, dtype=float),
                {"units": "Hz", "long_name": "frequency"},
            ),
            "sensor": np.asarray(sensors),
            "position": (
                "sensor",
                np.asarray(positions_m, dtype=float),
                {"units": "m", "long_name": "distance from the clamp"},
            ),
            "block": np.arange(block_h1.shape[0]),
        },
        attrs=dict(attrs),
    )


def complex_frf(ds: xr.Dataset, prefix: str = "h1") -> np.ndarray:
    """Return the complex FRF from the dataset's ``{prefix}_real`` and ``{prefix}_imag`` variables.

    Parameters
    ----------
    ds
        An FRF dataset (``frf_result_dataset``).
    prefix
        The variables' prefix: "h1" (the whole record's) or "block_h1" (the sub-records').

    Returns
    -------
    frf : np.ndarray
        The complex FRF [m/s^2/N], in the variables' shape: shape (n_sensors, n_f) for "h1",
        (n_blocks, n_sensors, n_f) for "block_h1".
    """
    return ds[f"{prefix}_real"].values + 1j * ds[f"{prefix}_imag"].values


def _sub_record_uncertainties(f, frf: xr.Dataset, n_modes: int, band_hz, order: int) -> tuple:
    """Return the standard uncertainties of the natural frequencies and damping ratios from the sub-records' fits.

    (standard uncertainty of the natural frequencies (Hz), of the damping ratios, sub-records fitted) from the
    spread of the sub-records' fits (batch means: std / sqrt(n_blocks)); NaN with fewer than two fitted.
    """
    blocks_f, blocks_z = [], []
    bh = complex_frf(frf, "block_h1")
    for b in range(bh.shape[0]):
        try:
            e = fit_modes(f, bh[b], n_modes, tuple(band_hz), order)
        except ValueError as exc:
            log.warning("sub-record %d: modal fit failed (%s)", b, exc)
            continue
        blocks_f.append(e.natural_frequency_hz)
        blocks_z.append(e.damping_ratio)
    if len(blocks_f) >= 2:
        sf = np.std(blocks_f, axis=0, ddof=1) / np.sqrt(len(blocks_f))
        sz = np.std(blocks_z, axis=0, ddof=1) / np.sqrt(len(blocks_z))
    else:
        sf = np.full(n_modes, np.nan)
        sz = np.full(n_modes, np.nan)
    return sf, sz, len(blocks_f)


def _order_spread(f, frf: xr.Dataset, est, n_modes: int, band_hz, order: int) -> np.ndarray:
    """Return the largest change of the natural frequencies of ``est`` at model order +-2.

    (n_modes,), in Hz: the poles must agree with neighbouring model orders (stabilisation check); NaN where no
    neighbouring order could be fitted.
    """
    spread = []
    for o in (order - 2, order + 2):
        try:
            spread.append(
                np.abs(
                    fit_modes(f, complex_frf(frf), n_modes, tuple(band_hz), o).natural_frequency_hz
                    - est.natural_frequency_hz
                )
            )
        except ValueError:
            pass
    return np.max(spread, axis=0) if spread else np.full(n_modes, np.nan)


def modal_dataset(frf: xr.Dataset, n_modes: int, band_hz: Sequence[float], order: int) -> xr.Dataset:
    """Return the natural frequencies and damping ratios of the first modes, with standard uncertainties.

    LSCF poles + LSFD residues; the standard uncertainties come from the spread of the sub-record estimates (batch
    means: std / sqrt(n_blocks)), and the order spread from the fits at model order +-2.

    Parameters
    ----------
    frf
        The FRF dataset (results/linear/frf.nc, ``frf_result_dataset``).
    n_modes
        Number of modes to identify (config ``modal.n_modes``).
    band_hz
        The analysis band (low, high) [Hz] (``modal.band_hz``).
    order
        LSCF model order (``modal.order``).

    Returns
    -------
    modal : xr.Dataset
        The modal dataset (results/linear/modal.nc): natural frequencies, their standard uncertainties and order
        spread (Hz), damping ratios and their standard uncertainties (1), the residues' magnitudes (sensor, mode).
    """
    f = frf["frequency"].values
    est = fit_modes(f, complex_frf(frf), n_modes, tuple(band_hz), order)
    sf, sz, n_blocks = _sub_record_uncertainties(f, frf, n_modes, band_hz, order)
    order_spread = _order_spread(f, frf, est, n_modes, band_hz, order)
    return xr.Dataset(
        {
            "natural_frequency": (
                "mode",
                est.natural_frequency_hz,
                {"units": "Hz", "long_name": "undamped natural frequency |s_r|/2pi"},
            ),
            "natural_frequency_std": (
                "mode",
                sf,
                {
                    "units": "Hz",
                    "long_name": "standard uncertainty of the natural frequency (sub-records)",
                    "nonfinite_meaning": "NaN: fewer than two sub-records could be fitted",
                },
            ),
            "order_spread": (
                "mode",
                order_spread,
                {
                    "units": "Hz",
                    "long_name": "change of the frequency at model order +-2",
                    "nonfinite_meaning": "NaN: no neighbouring order could be fitted",
                },
            ),
            "damping_ratio": ("mode", est.damping_ratio, {"units": "1", "long_name": "modal damping ratio"}),
            "damping_ratio_std": (
                "mode",
                sz,
                {
                    "units": "1",
                    "long_name": "standard uncertainty of the damping ratio",
                    "nonfinite_meaning": "NaN: fewer than two sub-records could be fitted",
                },
            ),
            "residue_abs": (
                ("sensor", "mode"),
                np.abs(est.residues),
                {"units": "m/(N s)", "long_name": "|residue R of the accelerance sum_r (iw)^2 R_r/(iw - s_r) + c.c.|"},
            ),
        },
        coords={"mode": np.arange(1, n_modes + 1), "sensor": frf["sensor"].values},
        attrs={
            "method": "LSCF poles + LSFD residues",
            "order": order,
            "band_low_hz": band_hz[0],
            "band_high_hz": band_hz[1],
            "n_blocks_used": n_blocks,
        },
    )


def stiction_dataset(modal: xr.Dataset, structure_cfg: Mapping, stiction_cfg: Mapping) -> xr.Dataset:
    """Return k_t and k_n of Eq. (13) fitted to the identified frequencies, with confidence intervals and profiles.

    Parameters
    ----------
    modal
        The modal dataset (results/linear/modal.nc): reads ``natural_frequency`` and ``natural_frequency_std``
        [Hz] (mode).
    structure_cfg
        The config's ``structure`` block (``parameters.structure_from_config``).
    stiction_cfg
        The config's ``stiction`` block: reads ``frequency_uncertainty_floor``, ``confidence``,
        ``stiffness_scale_sd``, ``k_t_bounds_n_per_m`` and ``k_n_bounds_n_per_m`` [N/m].

    Returns
    -------
    stiction : xr.Dataset
        The stiffness dataset (results/linear/stiction.nc): k_t, k_n and their intervals (N/m), the stiffness
        scale, the model's and the identified frequencies and their weights (Hz), the profile misfits over their
        grids, and the fit's flags and notes as attributes.
    """
    f_id = modal["natural_frequency"].values
    sigma = frequency_sigma(
        f_id, modal["natural_frequency_std"].values, float(stiction_cfg["frequency_uncertainty_floor"])
    )
    params = structure_from_config(structure_cfg, 1e7, 1e8)
    scale_sd = float(stiction_cfg.get("stiffness_scale_sd", 0.0))
    fit = stiction_stiffness(
        params,
        f_id,
        sigma,
        tuple(stiction_cfg.get("k_t_bounds_n_per_m", (1e5, 1e9))),
        tuple(stiction_cfg.get("k_n_bounds_n_per_m", (1e5, 1e11))),
        float(stiction_cfg["confidence"]),
        stiffness_scale_sd=scale_sd,
    )
    gt, pt = fit.profiles["k_t"]
    gn, pn = fit.profiles["k_n"]
    return xr.Dataset(
        {
            "k_t": ((), fit.k_t, {"units": "N/m", "long_name": "tangential contact stiffness at stiction (best fit)"}),
            "k_n": (
                (),
                fit.k_n,
                {"units": "N/m", "long_name": "normal contact stiffness (best fit; see k_n_bounded_above)"},
            ),
            "k_t_interval": (
                "bound",
                np.asarray(fit.k_t_interval),
                {
                    "units": "N/m",
                    "long_name": "confidence interval of k_t",
                    "nonfinite_meaning": "inf: the data do not bound k_t from above",
                },
            ),
            "k_n_interval": (
                "bound",
                np.asarray(fit.k_n_interval),
                {
                    "units": "N/m",
                    "long_name": "confidence interval of k_n",
                    "nonfinite_meaning": "inf: the data do not bound k_n from above",
                },
            ),
            "stiffness_scale": (
                (),
                fit.stiffness_scale,
                {
                    "units": "1",
                    "long_name": "Young's modulus over the config's at the best fit (stiction.stiffness_scale_sd)",
                },
            ),
            "model_frequency": (
                "mode",
                fit.model_frequencies_hz,
                {"units": "Hz", "long_name": "model natural frequency at the best fit"},
            ),
            "identified_frequency": ("mode", f_id, {"units": "Hz", "long_name": "identified natural frequency"}),
            "frequency_sigma": ("mode", sigma, {"units": "Hz", "long_name": "frequency uncertainty used as weight"}),
            "profile_k_t_chi2": ("k_t_grid", pt, {"units": "1", "long_name": "profile misfit over k_t"}),
            "profile_k_n_chi2": ("k_n_grid", pn, {"units": "1", "long_name": "profile misfit over k_n"}),
        },
        coords={
            "bound": ["lower", "upper"],
            "mode": modal["mode"].values,
            "k_t_grid": ("k_t_grid", gt, {"units": "N/m"}),
            "k_n_grid": ("k_n_grid", gn, {"units": "N/m"}),
        },
        attrs={
            "chi2_min": fit.chi2_min,
            "confidence": fit.confidence,
            "stiffness_scale_sd": scale_sd,
            "k_t_bounded": int(fit.k_t_bounded),
            "k_n_bounded_above": int(fit.k_n_bounded_above),
            "k_n_bounded_below": int(fit.k_n_bounded_below),
            "k_t_interval_note": "; ".join(fit.notes["k_t"]),
            "k_n_interval_note": "; ".join(fit.notes["k_n"]),
        },
    )


def contact_stiffness_for_modes(stiction: xr.Dataset, k_n_prior: float) -> tuple[float, float, str]:
    """Return the contact stiffnesses for the linear modes and how k_n was chosen.

    k_n is the best fit where the data bound k_n on both sides; otherwise the prior, raised to the lower bound if it
    lies below it.

    Parameters
    ----------
    stiction
        The stiffness dataset (``stiction_dataset``).
    k_n_prior
        The prior normal contact stiffness [N/m] (config ``stiction.k_n_prior_n_per_m``).

    Returns
    -------
    k_t : float
        Tangential contact stiffness, the best fit [N/m].
    k_n : float
        Normal contact stiffness [N/m].
    how : str
        How k_n was chosen: "best fit" or the prior's note.
    """
    k_t = float(stiction["k_t"])
    if int(stiction.attrs["k_n_bounded_above"]) and int(stiction.attrs["k_n_bounded_below"]):
        return k_t, float(stiction["k_n"]), "best fit"
    lower = float(stiction["k_n_interval"].values[0])
    return k_t, max(float(k_n_prior), lower), "prior (data bound k_n from one side only)"


def linear_modes_dataset(
    stiction: xr.Dataset, structure_cfg: Mapping, n_modes: int, grid_points: int, k_n_prior: float
) -> xr.Dataset:
    """Return the mass-normalised linear modes (Eq. 14) of the identified linear model.

    phi_i(x) on a grid, its slope, u_i, y_si, theta_si, the contact coordinates xi_i, eta_i and the values at the
    sensors and the driving point, with k_t, k_n (``contact_stiffness_for_modes``) and the stiffness scale used, and
    the stiffness fit's prior and weights as attributes (for a diagnosis that redoes the fit).

    Parameters
    ----------
    stiction
        The stiffness dataset (``stiction_dataset``).
    structure_cfg
        The config's ``structure`` block (reads ``sensors.names`` and what ``parameters.identified_structure``
        reads).
    n_modes
        Number of modes (config ``linear_modes.n_modes``).
    grid_points
        Number of points of the grid along the beam (``linear_modes.grid_points``).
    k_n_prior
        The prior normal contact stiffness [N/m] (``stiction.k_n_prior_n_per_m``).

    Returns
    -------
    modes : xr.Dataset
        The linear modes' dataset (results/linear/linear_modes.nc).
    """
    k_t, k_n, how = contact_stiffness_for_modes(stiction, k_n_prior)
    scale = float(stiction["stiffness_scale"]) if "stiffness_scale" in stiction else 1.0
    params = identified_structure(structure_cfg, {"k_t": k_t, "k_n": k_n, "stiffness_scale": scale})
    model = assemble(params)
    modes = structural_modes(model, n_modes)
    x = np.linspace(0.0, params.length, grid_points)
    phi, dphi = shape_on_grid(model, modes.shapes, x)
    V = modes.shapes
    attrs = {"k_n_choice": how, "normalisation": "phi^T M phi = 1"}
    # the stiffness fit's prior and weights, for a diagnosis that redoes the fit (``gap.model.IdentifiedModel``)
    attrs["stiffness_scale_sd"] = float(stiction.attrs.get("stiffness_scale_sd", 0.0))
    if "frequency_sigma" in stiction:
        attrs["frequency_sigma_hz"] = np.asarray(stiction["frequency_sigma"].values, dtype=float)
    return xr.Dataset(
        {
            "natural_frequency": (
                "mode",
                modes.frequencies_hz,
                {"units": "Hz", "long_name": "natural frequency of the linear model"},
            ),
            "phi": (
                ("x", "mode"),
                phi,
                {"units": "kg^-0.5", "long_name": "mass-normalised lateral mode shape phi_i(x)"},
            ),
            "dphi_dx": (("x", "mode"), dphi, {"units": "kg^-0.5/m", "long_name": "slope of the mode shape"}),
            "u": ("mode", V[model.u_dof], {"units": "kg^-0.5", "long_name": "axial tip motion u_i"}),
            "y_s": ("mode", V[model.ys_dof], {"units": "kg^-0.5", "long_name": "string stretch y_si"}),
            "theta_s": ("mode", V[model.thetas_dof], {"units": "rad kg^-0.5", "long_name": "pendulum angle theta_si"}),
            "xi": (
                "mode",
                model.xi_vector @ V,
                {"units": "kg^-0.5", "long_name": "tangential contact motion xi_i (Eq. 9, linear part)"},
            ),
            "eta": (
                "mode",
                model.eta_vector @ V,
                {"units": "kg^-0.5", "long_name": "normal contact motion eta_i (Eq. 8)"},
            ),
            "phi_sensor": (
                ("sensor", "mode"),
                model.sensor_vectors @ V,
                {"units": "kg^-0.5", "long_name": "mode shape at the sensors"},
            ),
            "phi_drive": (
                "mode",
                model.force_vector @ V,
                {"units": "kg^-0.5", "long_name": "mode shape at the driving point d_p"},
            ),
            "k_t": ((), k_t, {"units": "N/m", "long_name": "tangential contact stiffness used"}),
            "k_n": ((), k_n, {"units": "N/m", "long_name": "normal contact stiffness used"}),
            "stiffness_scale": (
                (),
                scale,
                {"units": "1", "long_name": "Young's modulus used over the config's (the stiffness fit's scale)"},
            ),
        },
        coords={
            "x": ("x", x, {"units": "m", "long_name": "distance from the clamp"}),
            "mode": np.arange(1, n_modes + 1),
            "sensor": list(structure_cfg["sensors"]["names"]),
        },
        attrs=attrs,
    )
