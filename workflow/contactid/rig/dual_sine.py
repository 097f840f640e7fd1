"""One response-controlled dual-sine test on the virtual rig: raw record + truth.

The excitation frequency is snapped to the record's frequency grid,
f = k fs / n_samples with k integer, so that the record holds exactly k periods
(as a test engineer sets a generator that shares the acquisition clock).
"""

from __future__ import annotations

import logging
from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from ..beam_model import assemble
from ..contact_laws import NormalLaw, ValanisParameters
from ..harmonics import harmonic_amplitudes
from ..io import raw_dataset
from ..random_streams import generator
from .control import ControlResult, control_response
from .damping import dual_sine_damping_ratios
from .effects import effect_magnitudes
from .frontend import add_noise, anti_alias_decimate, delay_channels
from .nonlinear import (
    ContactParameters,
    reduced_model,
    stable_oversampling,
)
from .simulator import DualSineSimulator
from .structure import channel_delays, channel_gains, rig_structure, true_structure_config

log = logging.getLogger(__name__)


# the response control's history, one variable per field (name, units, what): the forces it tried, the driving
# point's harmonics they gave, and whether the response had settled
CONTROL_FIELDS = (
    ("F1", "N", "force amplitude at w"),
    ("F3", "N", "force amplitude at 3 w"),
    ("A1", "m/s^2", "driving-point acceleration amplitude at w"),
    ("A3", "m/s^2", "driving-point acceleration amplitude at 3 w"),
    ("steady", "1", "1 where the response had settled"),
)


def dual_sine_settings(rig_cfg: Mapping, case_cfg: Mapping, sampling_rate_hz: float) -> dict:
    """Return the merged settings of one load case's dual-sine test.

    They are rig.dual_sine (at the schema's defaults where left out), overridden per case, with the excitation
    frequency snapped to the record's frequency grid f = k fs / record_samples (k whole periods in the record).

    Parameters
    ----------
    rig_cfg
        The config's ``rig`` section; its ``dual_sine`` block is read (excitation_frequency_hz, record_samples,
        n_modes, oversampling, control_tolerance, steady_state_tolerance).
    case_cfg
        The load case's block (``load_cases.<case>``); its ``excitation_frequency_hz``, where given, overrides the
        rig's.
    sampling_rate_hz
        The record's sampling rate [Hz].

    Returns
    -------
    settings : dict
        The rig.dual_sine keys with ``excitation_frequency_hz`` snapped to the grid (Hz), and ``periods`` (k, the
        whole periods in the record) and ``sampling_rate_hz`` (Hz) added.
    """
    from ..schema import schema_defaults

    s = {**schema_defaults("rig", "dual_sine"), **(rig_cfg.get("dual_sine") or {})}
    if "excitation_frequency_hz" in case_cfg:
        s["excitation_frequency_hz"] = case_cfg["excitation_frequency_hz"]
    n = int(s["record_samples"])
    k = max(1, int(round(float(s["excitation_frequency_hz"]) * n / sampling_rate_hz)))
    s["periods"] = k
    s["excitation_frequency_hz"] = k * sampling_rate_hz / n
    s["sampling_rate_hz"] = float(sampling_rate_hz)
    return s


def contact_parameters(structure_cfg: Mapping, rig_cfg: Mapping) -> ContactParameters:
    """Return the rig's true contact laws with the configured effects.

    Keys of ``rig.truth`` left out take the schema's defaults, for a config not validated by the Snakefile.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` section (its ``preload_n``, with ``rig.true_structure`` merged in).
    rig_cfg
        The config's ``rig`` section: ``truth.friction`` (the law's parameters and ``regularization``),
        ``truth.normal`` (``stiffness_at_preload_n_per_m``, ``exponent``, ``cubic_n_per_m3``), ``true_structure``
        and ``effects`` are read.

    Returns
    -------
    contact : ContactParameters
        The true friction and normal laws, the preload and the contact effects' magnitudes.
    """
    from ..schema import with_defaults

    truth = with_defaults({"rig": {"truth": rig_cfg["truth"]}})["rig"]["truth"]
    fr = ValanisParameters.from_config(truth["friction"])
    n0 = float(true_structure_config(structure_cfg, rig_cfg)["preload_n"])
    law = NormalLaw(n0, float(truth["normal"]["stiffness_at_preload_n_per_m"]), float(truth["normal"]["exponent"]))
    eff = effect_magnitudes(rig_cfg.get("effects"))
    return ContactParameters(
        friction=(fr.e_f, fr.k_c, fr.e_t, fr.kappa, fr.mu),
        preload=n0,
        static_approach=law.static_approach,
        exponent=law.exponent,
        hunt_crossley=eff["normal_contact_damping"],
        viscous=eff["viscous_friction"],
        iwan_share=eff["multi_asperity_friction"],
        preload_drift=eff["preload_drift"],
        regularization=str(truth["friction"]["regularization"]),
        cubic=float(truth["normal"]["cubic_n_per_m3"]),
    )


def normal_tangent_ratio(contact: ContactParameters, k_n: float, load: float) -> float:
    """Return the normal law's tangent stiffness where the compression reaches ``load`` x N0, over k_n.

    The law is the integrator's and the tangent the harmonic balance's (``normal_path``), at the compression found by
    ``brentq``.

    Parameters
    ----------
    contact
        The rig's contact laws (preload N0, the normal law's static approach, exponent and cubic hardening).
    k_n
        The reduced model's linear normal contact stiffness [N/m].
    load
        The total normal force where the tangent is taken, a multiple of the preload N0 [-].

    Returns
    -------
    ratio : float
        The tangent stiffness over ``k_n`` [-], at least 1.
    """
    from scipy.optimize import brentq

    from .periodic_path import normal_path

    c = contact

    def normal(eta):  # N (N) and dN/deta (N/m) of the elastic law
        N, dN, dNd = np.empty(1), np.empty(1), np.empty(1)
        normal_path(
            np.array([eta]), np.zeros(1), c.preload, c.static_approach, c.exponent, c.cubic, 0.0, True, N, dN, dNd
        )
        return N[0], dN[0]

    hi = c.static_approach  # compression -eta; doubled until N passes load x N0
    while normal(-hi)[0] < load * c.preload:
        hi *= 2.0
    eta = -brentq(lambda x: normal(-x)[0] - load * c.preload, 0.0, hi, xtol=1e-15)
    return max(1.0, -normal(eta)[1] / k_n)


def build_simulator(
    structure_cfg: Mapping,
    rig_cfg: Mapping,
    settings: Mapping,
    n_modes: int | None = None,
    oversampling: int | None = None,
) -> DualSineSimulator:
    """Return the rig's reduced model and integrator for the dual-sine tests.

    The oversampling is raised where explicit central differences need it (``stable_oversampling``: a margin on
    omega_max dt and on the viscous friction's rate), with a hardening normal law's tangent where N reaches 3 N0.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` section.
    rig_cfg
        The config's ``rig`` section (its ``true_structure``, ``fe_elements``, ``truth``, ``true_damping`` and
        ``effects`` are read).
    settings
        The test's settings (``dual_sine_settings``): ``n_modes``, ``oversampling`` and ``sampling_rate_hz`` are
        read.
    n_modes
        Modes of the reduced model (None: the settings').
    oversampling
        Integration steps per sample before the stability margin (None: the settings').

    Returns
    -------
    simulator : DualSineSimulator
        The integrator, its ``oversampling`` the steps per sample it uses.
    """
    params = rig_structure(structure_cfg, rig_cfg)
    model = assemble(params)
    red = reduced_model(model, int(n_modes or settings["n_modes"]))
    eff = effect_magnitudes(rig_cfg.get("effects"))
    zeta = dual_sine_damping_ratios(rig_cfg, red.omega / (2 * np.pi))
    zeta[red.beam_mode] += eff["structural_damping"]
    q = int(oversampling or settings["oversampling"])
    contact = contact_parameters(structure_cfg, rig_cfg)
    # explicit central differences: a margin on omega_max dt and on the viscous friction's rate (stable_oversampling);
    # a hardening normal law stiffens the normal shape: take its tangent where N reaches 3 N0
    stiffening = np.sqrt(normal_tangent_ratio(contact, red.k_n, 3.0))
    q = stable_oversampling(red, settings["sampling_rate_hz"], q, stiffening, eff["viscous_friction"])
    sim = DualSineSimulator(red, contact, zeta, 1.0 / (q * settings["sampling_rate_hz"]))
    sim.oversampling = q
    return sim


def energy_balance(out: dict, sim: DualSineSimulator) -> dict:
    """Return the energies over the recorded (integer-period) window and the balance's relative residual.

    Parameters
    ----------
    out
        The simulated signals over the window at the integration rate (``DualSineSimulator.run``'s): the force
        ``f`` (N), the modal velocities ``v``, the friction force ``S`` (N) and slip rate ``dxi`` (m/s), the normal
        force ``N`` (N) and the normal rate ``deta`` (m/s).
    sim
        The simulator that ran them (its step, damping ratios, reduced model and preload are read).

    Returns
    -------
    energies : dict
        ``input_work_j``, ``damping_work_j`` (modal damping), ``friction_work_j``, ``normal_work_j`` (normal-contact
        dissipation), all in J, and ``energy_residual``, (input - dissipated) / input.
    """
    dt = sim.dt
    r = sim.red
    v_drive = out["v"] @ r.drive
    w_in = np.sum(out["f"] * v_drive) * dt
    c = 2 * sim.zeta * r.omega
    w_damp = np.sum((out["v"] ** 2) @ c) * dt
    w_fric = np.sum(out["S"] * out["dxi"]) * dt
    w_norm = -np.sum((out["N"] - sim.contact.preload) * out["deta"]) * dt
    dissipated = w_damp + w_fric + w_norm
    return {
        "input_work_j": float(w_in),
        "damping_work_j": float(w_damp),
        "friction_work_j": float(w_fric),
        "normal_work_j": float(w_norm),
        "energy_residual": float((w_in - dissipated) / w_in),
    }


def _response_targets(case_cfg: Mapping, eff: Mapping) -> tuple[float, float]:
    """Return the driving-point targets (A1, A3) of the load case (m/s^2), scaled by the contact separation."""
    scale = eff["contact_separation"] or 1.0
    return (scale * float(case_cfg["A1_m_per_s2"]), scale * float(case_cfg["A2_m_per_s2"]))


def _log_control_outcome(case: str, ctl: ControlResult, target: tuple, n_samples: int) -> None:
    """Log whether the response control converged.

    A warning with the last force (N) and response (m/s^2) where it did not.
    """
    if not ctl.converged:
        F1, F3, A1, A3, steady = ctl.history[-1]
        log.warning(
            "%s: response control did not converge in %d iterations: F1 = %.4g N, F3 = %.4g N give "
            "A1 = %.4g, A3 = %.4g m/s^2 (targets %.4g, %.4g)%s",
            case,
            len(ctl.history),
            F1,
            F3,
            A1,
            A3,
            target[0],
            target[1],
            "" if steady else ", not steady",
        )
    else:
        log.info(
            "%s: response control converged in %d iterations; recording %d samples", case, len(ctl.history), n_samples
        )


def _recorded_response(sim: DualSineSimulator, ctl: ControlResult, w: float, n_samples: int) -> tuple[dict, int, int]:
    """Return the simulated response at the controlled force (``run``'s dict at the integration rate).

    It covers the record of ``n_samples`` samples with a margin of 512 samples either side for the anti-alias filter;
    a preload drift (effect) runs over the record. Returns (signals, steps of the record, steps of one margin).
    """
    q = sim.oversampling
    n_rec = n_samples * q
    margin = 64 * q * 8
    # preload drift (effect) runs over the recorded window
    if sim.contact.preload_drift:
        sim.drift_t0 = sim.t + margin * sim.dt
        sim.drift_rate = sim.contact.preload_drift / (n_rec * sim.dt)
    out = sim.run(ctl.F1, ctl.F3, w, n_rec + 2 * margin, store_from=0)
    return out, n_rec, margin


def _measured_record(
    out: dict,
    sim: DualSineSimulator,
    rig_cfg: Mapping,
    margin: int,
    n_rec: int,
    noise_fraction: float,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """Return the force (N) and accelerations (m/s^2, (sensors, samples)) as the front end records them.

    The front end applies channel delays and sensitivity errors if those effects are on, anti-alias filtering and
    decimation to the sampling rate over the record, and sensor noise (``noise_fraction`` of each channel's rms, from
    ``rng``).
    """
    q = sim.oversampling
    acc_sim = out["a"] @ sim.red.sensors.T  # (n, sensors)
    acc_sim = acc_sim.T
    delays = channel_delays(rig_cfg, acc_sim.shape[0])
    if delays is not None:
        acc_sim = delay_channels(acc_sim, delays, 1.0 / sim.dt)
    gains = channel_gains(rig_cfg, acc_sim.shape[0])
    if gains is not None:
        acc_sim = acc_sim * np.asarray(gains)[:, None]
    acc = anti_alias_decimate(acc_sim, q)[:, margin // q : (margin + n_rec) // q]
    force = anti_alias_decimate(out["f"], q)[margin // q : (margin + n_rec) // q]
    force = add_noise(force, noise_fraction, rng)
    acc = add_noise(acc, noise_fraction, rng)
    return force, acc


def _stationarity_changes(rec: dict, sim: DualSineSimulator, w: float, n_rec: int) -> tuple[float, float]:
    """Return the stationarity of the recorded window.

    It is the relative change of the driving-point harmonics |A1| and |A3| from the first to the last third of the
    record.
    """
    drive = rec["a"] @ sim.red.drive
    third = n_rec // 3
    h_first = np.abs(harmonic_amplitudes(drive[:third], rec["t"][:third], w, (1, 3)))
    h_last = np.abs(harmonic_amplitudes(drive[-third:], rec["t"][-third:], w, (1, 3)))
    return float(abs(h_last[0] / h_first[0] - 1)), float(abs(h_last[1] / h_first[1] - 1))


def _truth_variables(rec: dict, sim: DualSineSimulator, ctl: ControlResult, sub: slice) -> dict:
    """Return the truth's data variables.

    They are the contact forces and motions, the force and accelerations without front end or noise and the reduced
    coordinates at the sampling rate (``sub`` of the record), the reduced basis' frequencies and the control and
    steady-state histories.
    """
    red = sim.red
    hist = np.array(ctl.history, dtype=float)
    return {
        "S": ("time", rec["S"][sub], {"units": "N", "long_name": "true friction force S(t)"}),
        "N": (
            "time",
            rec["N"][sub],
            {"units": "N", "long_name": "true total normal force N(t) (compression positive)"},
        ),
        "xi": ("time", rec["xi"][sub], {"units": "m", "long_name": "true tangential contact motion xi(t), Eq. 9"}),
        "eta": ("time", rec["eta"][sub], {"units": "m", "long_name": "true normal contact motion eta(t), Eq. 8"}),
        "xi_dot": ("time", rec["dxi"][sub], {"units": "m/s", "long_name": "true tangential contact velocity"}),
        "eta_dot": ("time", rec["deta"][sub], {"units": "m/s", "long_name": "true normal contact velocity"}),
        "force_true": ("time", rec["f"][sub], {"units": "N", "long_name": "excitation force without noise"}),
        "acceleration_true": (
            ("sensor", "time"),
            (rec["a"] @ red.sensors.T)[sub].T,
            {"units": "m/s^2", "long_name": "accelerations without front end or noise"},
        ),
        "reduced_coordinate": (
            ("time", "reduced_mode"),
            rec["z"][sub],
            {"units": "kg^0.5 m", "long_name": "coordinates of the rig's reduced basis"},
        ),
        "reduced_frequency": (
            "reduced_mode",
            red.omega / (2 * np.pi),
            {"units": "Hz", "long_name": "frequencies of the rig's reduced stuck basis"},
        ),
        **{
            f"control_{name}": ("iteration", hist[:, k], {"units": unit, "long_name": f"response control: {what}"})
            for k, (name, unit, what) in enumerate(CONTROL_FIELDS)
        },
        "steady_state_change": (
            "chunk",
            np.asarray(ctl.steady_state.change or [np.nan]),
            {
                "units": "1",
                "long_name": "relative change of the driving-point harmonics between 8-period chunks",
                "nonfinite_meaning": "NaN: the first chunk already met the tolerance",
            },
        ),
    }


def _truth_attrs(
    ctl: ControlResult, target: tuple, s: Mapping, eff: Mapping, sim: DualSineSimulator, stationarity, energy
) -> dict:
    """Return the truth's attributes.

    They are the controlled force amplitudes (N) and response (m/s^2) with their targets, the stationarity changes
    (``stationarity``: A1, A3), the effects, the true contact laws, the linear contact springs (N/m), the energy
    balance (J) and the test's settings ``s``.
    """
    c = sim.contact
    return {
        "F1_n": ctl.F1,
        "F3_n": ctl.F3,
        "A1_m_per_s2": ctl.A1,
        "A2_m_per_s2": ctl.A3,
        "target_A1_m_per_s2": target[0],
        "target_A2_m_per_s2": target[1],
        "control_converged": int(ctl.converged),
        "excitation_frequency_hz": s["excitation_frequency_hz"],
        "periods": s["periods"],
        "stationarity_change_a1": stationarity[0],
        "stationarity_change_a3": stationarity[1],
        "effects": str({k: v for k, v in eff.items() if v}),
        **{f"friction_{k}": v for k, v in zip(("e_f", "k_c", "e_t", "kappa", "mu"), c.friction)},
        "preload_n": c.preload,
        "normal_static_approach_m": c.static_approach,
        "normal_exponent": c.exponent,
        "normal_cubic_n_per_m3": c.cubic,
        "friction_regularization": c.regularization,
        "k_t": sim.red.k_t,
        "k_n": sim.red.k_n,
        **{f"energy_{k}": v for k, v in energy.items()},
        **{f"setting_{k}": v for k, v in s.items()},
    }


def dual_sine_test(
    structure_cfg: Mapping,
    rig_cfg: Mapping,
    case_cfg: Mapping,
    sampling_rate_hz: float,
    noise_fraction: float,
    seed: int,
    case: str,
    sensor_names: Sequence[str],
) -> tuple[xr.Dataset, xr.Dataset]:
    """Run the response-controlled dual-sine test of one load case.

    The force amplitudes F1, F3 at w and 3 w are tuned until the driving point's harmonics reach the load case's
    targets (``control_response``), then the record is simulated and passed through the front end.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` section (its ``sensors.positions_m`` name the record's sensor positions).
    rig_cfg
        The config's ``rig`` section (``dual_sine``, ``truth``, ``true_structure``, ``true_damping``, ``effects``,
        ...).
    case_cfg
        The load case's block: ``A1_m_per_s2``, ``A2_m_per_s2`` (the targets at w and 3 w, m/s^2) and optionally
        ``excitation_frequency_hz``.
    sampling_rate_hz
        The record's sampling rate [Hz].
    noise_fraction
        The sensor noise's rms, a fraction of each channel's rms [-].
    seed
        The random seed (the noise's stream is ``<case>/noise``).
    case
        The load case's name.
    sensor_names
        The accelerometers' names, one per sensor.

    Returns
    -------
    raw : xr.Dataset
        The raw record: force and accelerations only (with anti-alias filtering, channel delays and sensitivity
        errors if those effects are on, and sensor noise).
    truth : xr.Dataset
        S, N, xi, eta, the reduced coordinates, the force amplitudes, the control and steady-state histories and
        the energy balance.
    """
    s = dual_sine_settings(rig_cfg, case_cfg, sampling_rate_hz)
    eff = effect_magnitudes(rig_cfg.get("effects"))
    target = _response_targets(case_cfg, eff)
    sim = build_simulator(structure_cfg, rig_cfg, s)
    w = 2 * np.pi * s["excitation_frequency_hz"]
    log.info(
        "%s: response control to A1 = %.4g, A3 = %.4g m/s^2 at %.4g Hz (%d modes, %d steps per sample)",
        case,
        target[0],
        target[1],
        s["excitation_frequency_hz"],
        sim.red.omega.size,
        sim.oversampling,
    )
    ctl = control_response(sim, target[0], target[1], w, tol=float(s["control_tolerance"]))
    n_out = int(s["record_samples"])
    _log_control_outcome(case, ctl, target, n_out)
    out, n_rec, margin = _recorded_response(sim, ctl, w, n_out)
    win = slice(margin, margin + n_rec)
    rec = {k: v[win] for k, v in out.items()}
    energy = energy_balance(rec, sim) if not sim.contact.preload_drift else {}
    rng = generator(seed, f"{case}/noise")
    force, acc = _measured_record(out, sim, rig_cfg, margin, n_rec, noise_fraction, rng)
    time = np.arange(n_out) / sampling_rate_hz
    stationarity = _stationarity_changes(rec, sim, w, n_rec)
    raw = raw_dataset(
        time,
        force,
        acc,
        sensor_names,
        tuple(structure_cfg["sensors"]["positions_m"]),
        sampling_rate_hz,
        attrs={"test": "dual_sine", "excitation_frequency_hz": s["excitation_frequency_hz"]},
    )
    truth = xr.Dataset(
        _truth_variables(rec, sim, ctl, slice(0, n_rec, sim.oversampling)),
        coords={
            "time": ("time", time, {"units": "s", "long_name": "time"}),
            "sensor": list(sensor_names),
        },
        attrs=_truth_attrs(ctl, target, s, eff, sim, stationarity, energy),
    )
    return raw, truth
