"""Virtual rig, linear part: the low-level random test of Section 3.

The structure is the linear FE model with the contact stuck (its springs are
the small-amplitude limit of the contact laws) and a small modal damping.
Each mode is integrated exactly for a piecewise-linear force (first-order hold
discretisation), at ``oversampling`` times the output rate; the channels then
pass the same anti-alias FIR filter and decimator, as a data-acquisition front
end does, and receive independent Gaussian sensor noise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Mapping

import numpy as np
import scipy.signal
from numba import njit

from ..beam_model import FEModel
from ..beam_modes import all_modes
from ..random_streams import generator
from .damping import damping_ratios
from .frontend import add_noise, anti_alias_decimate, delay_channels

if TYPE_CHECKING:
    import xarray as xr


@dataclass(frozen=True)
class RandomTestSettings:
    """Settings of the random test (SI units).

    Attributes
    ----------
    sampling_rate_hz
        Output sampling rate [Hz].
    duration_s
        Recorded length [s].
    band_hz
        (low, high) band of the random force [Hz].
    force_rms_n
        The random force's rms [N].
    noise_fraction
        Sensor noise rms as a fraction of each channel's rms [-].
    modal_damping_ratio
        Damping ratio [-] at damping_reference_hz, spread over the modes by damping_form (see ``rig.damping``).
    oversampling
        Internal integration rate over output rate.
    settle_s
        Discarded start-up time [s].
    channel_delays_s
        Per-accelerometer sampling delay [s] (effect channel_time_skew), or None.
    channel_gains
        Per-accelerometer sensitivity factor [-] (effect channel_gain_error), or None.
    damping_form
        How the damping ratio spreads over the modes ("modal", "stiffness_proportional", "mass_proportional",
        "rayleigh"; ``rig.damping``).
    damping_reference_hz
        The frequency at which the form gives modal_damping_ratio [Hz].
    """

    sampling_rate_hz: float = 5120.0
    duration_s: float = 128.0  # the schema's default (tests/test_config.py checks they agree)
    band_hz: tuple[float, float] = (5.0, 1000.0)
    force_rms_n: float = 0.5
    noise_fraction: float = 0.005
    modal_damping_ratio: float = 0.005
    oversampling: int = 4
    settle_s: float = 2.0
    channel_delays_s: tuple | None = None
    channel_gains: tuple | None = None
    damping_form: str = "modal"
    damping_reference_hz: float = 54.4


@dataclass(frozen=True)
class RandomTestRecord:
    """Raw random-test signals.

    Attributes
    ----------
    time
        Sample times [s], shape (n_t,).
    force
        Force at d_p [N], shape (n_t,).
    acceleration
        Accelerations at the sensors [m/s^2], shape (n_sensors, n_t).
    """

    time: np.ndarray
    force: np.ndarray
    acceleration: np.ndarray


def modal_acceleration_filters(
    model: FEModel, damping_ratio: float | Callable[[np.ndarray], np.ndarray], dt: float
) -> tuple[list, np.ndarray]:
    """Build discrete (b, a) filters from the force at d_p to each modal acceleration, FOH-exact for every mode.

    Modes above the simulation's Nyquist frequency are left out: their acceleration response below the output band
    edge is below (f_band / f_Nyquist)^2 of their (already tiny) quasi-static part.

    Parameters
    ----------
    model
        The FE model (the contact stuck).
    damping_ratio
        One damping ratio [-] for every mode, or a function of the modes' frequencies [Hz], shape (n_modes,), giving
        each its ratio, shape (n_modes,).
    dt
        The simulation's time step [s].

    Returns
    -------
    filters : list
        One (b, a) pair per mode kept (below the Nyquist frequency 0.5 / dt), lowest first: the discrete transfer
        function from the force [N] to the mass-normalised modal acceleration [m kg^0.5/s^2].
    sensor_participation : np.ndarray
        The mass-normalised mode shapes at the sensors [kg^-0.5], shape (n_sensors, n_modes), n_modes the modes
        kept.
    """
    modes = all_modes(model)
    keep = modes.frequencies_hz < 0.5 / dt
    phi = modes.shapes[:, keep]
    wn = 2 * np.pi * modes.frequencies_hz[keep]
    zetas = damping_ratio(wn / (2 * np.pi)) if callable(damping_ratio) else np.full(wn.size, float(damping_ratio))
    b_force = phi.T @ model.force_vector
    sens = model.sensor_vectors @ phi
    filters = []
    for w, bf, damping_ratio in zip(wn, b_force, zetas):
        # q'' + 2 zeta w q' + w^2 q = bf f;  a = q'' = -w^2 q - 2 zeta w q' + bf f
        A = np.array([[0.0, 1.0], [-(w**2), -2 * damping_ratio * w]])
        B = np.array([[0.0], [bf]])
        C = np.array([[-(w**2), -2 * damping_ratio * w]])
        D = np.array([[bf]])
        Ad, Bd, Cd, Dd, _ = scipy.signal.cont2discrete((A, B, C, D), dt, method="foh")
        num, den = scipy.signal.ss2tf(Ad, Bd, Cd, Dd)
        filters.append((np.real(num[0]), np.real(den)))
    return filters, sens


@njit(cache=True)
def _filtered_modal_sum(f, b, a, weights, out):
    """Write out[c, i] = sum over modes m (in order) of weights[c, m] y_m[i].

    y_m is the second-order filter (b[m], a[m], normalised by a[m, 0]) of f in the direct form II transposed, as
    scipy.signal.lfilter computes it.
    """
    n_modes, n_channels = b.shape[0], weights.shape[0]
    z0 = np.zeros(n_modes)
    z1 = np.zeros(n_modes)
    acc = np.zeros(n_channels)
    for i in range(f.size):
        x = f[i]
        acc[:] = 0.0
        for m in range(n_modes):
            y = z0[m] + b[m, 0] * x
            z0[m] = z1[m] + x * b[m, 1] - y * a[m, 1]
            z1[m] = x * b[m, 2] - y * a[m, 2]
            for c in range(n_channels):
                acc[c] += y * weights[c, m]
        for c in range(n_channels):
            out[c, i] = acc[c]


def modal_acceleration_sum(force: np.ndarray, filters: list, sensor_participation: np.ndarray) -> np.ndarray:
    """Return the accelerations at the sensors: each mode's filter applied to the force, summed with its participation.

    Mode by mode, in one pass over the record with every mode's filter state at once: the same numbers as
    scipy.signal.lfilter per mode and a sum over the modes, bit for bit (tests/test_rig_and_io.py), in about half the
    time (0.73 -> 0.41 s for the 130 s random test at 20 kHz).

    Parameters
    ----------
    force
        The force at d_p [N], shape (n_t,).
    filters
        Each mode's (b, a) filter (``modal_acceleration_filters``), second order at most.
    sensor_participation
        The mode shapes at the sensors [kg^-0.5], shape (n_sensors, n_modes).

    Returns
    -------
    acceleration : np.ndarray
        The accelerations at the sensors [m/s^2], shape (n_sensors, n_t).
    """
    b = np.array([np.pad(num, (0, 3 - num.size)) / den[0] for num, den in filters]).reshape(-1, 3)
    a = np.array([np.pad(den, (0, 3 - den.size)) / den[0] for num, den in filters]).reshape(-1, 3)
    w = np.ascontiguousarray(sensor_participation, dtype=float)
    out = np.zeros((w.shape[0], np.size(force)))
    _filtered_modal_sum(np.ascontiguousarray(force, dtype=float), b, a, w, out)
    return out


def simulate_random_test(model: FEModel, settings: RandomTestSettings, seed: int) -> RandomTestRecord:
    """Simulate force and accelerations of the low-level random test.

    Parameters
    ----------
    model
        The rig's FE model (the contact stuck).
    settings
        The test's settings.
    seed
        The random seed (the force and the noise draw from their own streams of it).

    Returns
    -------
    record : RandomTestRecord
        The recorded time, force and accelerations (after the anti-alias filter, the decimation and the noise).
    """
    s = settings
    q = int(s.oversampling)
    fs_sim = s.sampling_rate_hz * q
    n_out = int(round(s.duration_s * s.sampling_rate_hz))
    n_settle = int(round(s.settle_s * s.sampling_rate_hz))
    n_sim = (n_out + n_settle) * q

    rng_force = generator(seed, "random_test/force")
    white = rng_force.standard_normal(n_sim)
    lo, hi = s.band_hz
    sos = scipy.signal.butter(8, [lo, hi], btype="bandpass", fs=fs_sim, output="sos")
    f_sim = scipy.signal.sosfilt(sos, white)
    f_sim *= s.force_rms_n / np.std(f_sim[n_settle * q :])

    filters, sens = modal_acceleration_filters(
        model, lambda f: damping_ratios(f, s.modal_damping_ratio, s.damping_form, s.damping_reference_hz), 1.0 / fs_sim
    )
    acc_sim = modal_acceleration_sum(f_sim, filters, sens)

    if s.channel_delays_s is not None:
        acc_sim = delay_channels(acc_sim, s.channel_delays_s, fs_sim)
    if s.channel_gains is not None:
        acc_sim = acc_sim * np.asarray(s.channel_gains)[:, None]
    force = anti_alias_decimate(f_sim, q)[n_settle : n_settle + n_out]
    acc = anti_alias_decimate(acc_sim, q)[:, n_settle : n_settle + n_out]
    rng_noise = generator(seed, "random_test/noise")
    force = add_noise(force, s.noise_fraction, rng_noise)
    acc = add_noise(acc, s.noise_fraction, rng_noise)
    time = np.arange(n_out) / s.sampling_rate_hz
    return RandomTestRecord(time, force, acc)


def settings_from_config(random_test_cfg: Mapping | None, rig_cfg: Mapping, n_channels: int = 3) -> RandomTestSettings:
    """Build the RandomTestSettings from the ``random_test`` and ``rig`` config blocks.

    Keys left out take the schema's defaults.

    Parameters
    ----------
    random_test_cfg
        The config's ``random_test`` block: ``sampling_rate_hz``, ``duration_s``, ``band_hz`` and ``force_rms_n`` are
        read; None: the defaults.
    rig_cfg
        The config's ``rig`` block: ``noise_fraction``, ``modal_damping_ratio``, ``oversampling``,
        ``true_damping`` (``form``, ``reference_frequency_hz``) and the effects channel_time_skew and
        channel_gain_error are read.
    n_channels
        The number of accelerometers.

    Returns
    -------
    settings : RandomTestSettings
        The test's settings.
    """
    from ..schema import schema_defaults
    from .structure import channel_delays, channel_gains

    rt = {**schema_defaults("random_test"), **dict(random_test_cfg or {})}
    rig_defaults = schema_defaults("rig")
    rig = {**rig_defaults, **dict(rig_cfg or {})}
    td = {**rig_defaults["true_damping"], **(rig.get("true_damping") or {})}
    return RandomTestSettings(
        sampling_rate_hz=float(rt["sampling_rate_hz"]),
        duration_s=float(rt["duration_s"]),
        band_hz=tuple(float(x) for x in rt["band_hz"]),
        force_rms_n=float(rt["force_rms_n"]),
        noise_fraction=float(rig["noise_fraction"]),
        modal_damping_ratio=float(rig["modal_damping_ratio"]),
        oversampling=int(rig["oversampling"]),
        channel_delays_s=channel_delays(rig_cfg, n_channels),
        channel_gains=channel_gains(rig_cfg, n_channels),
        damping_form=str(td["form"]),
        damping_reference_hz=float(td["reference_frequency_hz"]),
    )


def random_test_datasets(
    structure_cfg: Mapping, rig_cfg: Mapping, random_test_cfg: Mapping | None, seed: int, n_truth_modes: int = 6
) -> tuple[xr.Dataset, xr.Dataset]:
    """Return the raw record and the truth of the rig's random test as two xarray Datasets.

    The raw dataset holds only what a real test records; the truth holds the rig's parameters, exact natural
    frequencies and mode shapes at the sensors.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block (its ``sensors``' ``names`` and ``positions_m`` name the raw record's
        sensors).
    rig_cfg
        The config's ``rig`` block.
    random_test_cfg
        The config's ``random_test`` block; None: the defaults.
    seed
        The random seed.
    n_truth_modes
        How many modes the truth lists.

    Returns
    -------
    raw : xr.Dataset
        The raw record in the format of ``contactid.io``.
    truth : xr.Dataset
        The true natural frequencies (Hz), damping ratios and mass-normalised mode shapes at the sensors, k_t and
        k_n (N/m), and the rig's parameters as attributes.
    """
    import dataclasses

    import xarray as xr

    from ..beam_model import assemble
    from ..beam_modes import structural_modes
    from ..io import raw_dataset
    from .structure import rig_structure

    params = rig_structure(structure_cfg, rig_cfg)
    model = assemble(params)
    settings = settings_from_config(random_test_cfg, rig_cfg, len(params.sensor_positions))
    rec = simulate_random_test(model, settings, seed)
    names = structure_cfg["sensors"]["names"]
    # the raw record names the sensors where the tester believes them (the nominal structure)
    raw = raw_dataset(
        rec.time,
        rec.force,
        rec.acceleration,
        names,
        tuple(structure_cfg["sensors"]["positions_m"]),
        settings.sampling_rate_hz,
        attrs={"test": "random"},
    )
    modes = structural_modes(model, n_truth_modes)
    truth = xr.Dataset(
        {
            "natural_frequency": (
                "mode",
                modes.frequencies_hz,
                {"units": "Hz", "long_name": "true undamped natural frequency"},
            ),
            "damping_ratio": (
                "mode",
                damping_ratios(
                    modes.frequencies_hz,
                    settings.modal_damping_ratio,
                    settings.damping_form,
                    settings.damping_reference_hz,
                ),
                {"units": "1", "long_name": "true modal damping ratio"},
            ),
            "mode_shape_at_sensor": (
                ("sensor", "mode"),
                model.sensor_vectors @ modes.shapes,
                {"units": "kg^-0.5", "long_name": "mass-normalised mode shape at the sensors"},
            ),
            "k_t": ((), params.k_t, {"units": "N/m", "long_name": "true tangential contact stiffness at stiction"}),
            "k_n": ((), params.k_n, {"units": "N/m", "long_name": "true normal contact stiffness at the preload"}),
        },
        coords={"mode": np.arange(1, n_truth_modes + 1), "sensor": list(names)},
        attrs={
            f"param_{k}": (str(v) if isinstance(v, (tuple, bool)) else v) for k, v in dataclasses.asdict(params).items()
        },
    )
    return raw, truth
