"""Where the gap lies: by stage of the chain, by sensor, harmonic, part of the cycle and load case.

The stages are the accelerations, the generalized coordinates, the contact forces identified from the records against
the laws, the energy per cycle and the random test's FRF; with them, the stage evidence the place is told from (the
records' drift and settling, the inverse identification's noise, how far the structures the random test allows move
eta).
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np
import xarray as xr

from ..beam_modes import all_modes, structural_modes
from ..harmonics import periodic_grid
from ..modal_damping import modal_damping_vector
from .model import NONE, Augmentation, IdentifiedModel, fe_model
from .place import DEFAULT_PLACE, PlaceThresholds, open_fraction
from .place import place as _place_of
from .records import RecordHarmonics
from .refit import contact_grids, identified_forces, law_friction_force

if TYPE_CHECKING:
    from ..parameters import StructureParameters
    from .calibration import Calibration
    from .settings import GapSettings
    from .simulation import SimResult

log = logging.getLogger(__name__)


def relative_difference(a: np.ndarray, b: np.ndarray) -> float:
    """Return ||a - b|| / ||b||: how far ``a`` is from ``b``, relative to ``b``.

    Parameters
    ----------
    a
        The values compared [unit of b], shape (n_1, ..., n_k), any.
    b
        The reference [unit of a], shape (n_1, ..., n_k) as ``a``.

    Returns
    -------
    difference : float
        The relative difference (2-norm, Frobenius for matrices) [-].
    """
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(np.linalg.norm(b), 1e-300))


def cycle_parts(g: dict, k_t: float) -> dict:
    """Return masks of the parts of one period of the identified motion and forces.

    Velocity reversal (within 4 % of the period of a sign change of dxi/dt), peak compression (N in the top 10 % of
    its range), slip (tangent stiffness dS/dxi below half of k_t, outside the reversals) and stick (the rest).

    Parameters
    ----------
    g
        One period of the identified motion and forces (``refit.contact_grids``): xi [m], xi_dot [m/s], N [N] and S
        [N], each of shape (m,).
    k_t
        The tangential contact stiffness at stiction [N/m].

    Returns
    -------
    masks : dict
        stick, slip, velocity_reversal and peak_compression: boolean arrays of shape (m,) (peak compression overlaps
        the others).
    """
    m = g["xi"].size
    xd = g["xi_dot"]
    rev_idx = np.flatnonzero(np.sign(xd) != np.sign(np.roll(xd, 1)))
    reversal = np.zeros(m, bool)
    width = max(1, int(0.04 * m))
    for i in rev_idx:
        reversal[(np.arange(-width, width + 1) + i) % m] = True
    N = g["N"]
    peak = N >= N.max() - 0.1 * (N.max() - N.min())
    dS = np.gradient(g["S"]) / np.where(np.abs(np.gradient(g["xi"])) > 0, np.gradient(g["xi"]), np.nan)
    slip = (np.abs(dS) < 0.5 * k_t) & ~reversal
    stick = ~(reversal | slip)
    return {"stick": stick, "slip": slip, "velocity_reversal": reversal, "peak_compression": peak}


def _response_gaps(fe, records: dict, sims: dict, H: int) -> dict:
    """Return the gap of the accelerations and of the generalized coordinates per load case, by sensor and harmonic.

    The generalized coordinates are the sensors projected on the first structural modes; rows are load cases.
    """
    cases = list(records)
    phi_s = fe.sensor_vectors @ structural_modes(fe, min(3, len(records[cases[0]].sensors))).shapes
    pinv = np.linalg.pinv(phi_s)
    out = {"accelerations": [], "generalized_coordinates": [], "by_sensor": [], "by_harmonic": []}
    for c in cases:
        A, As = records[c].acceleration[:, :H], sims[c].acceleration[:, :H]
        out["accelerations"].append(relative_difference(As, A))
        out["generalized_coordinates"].append(relative_difference(pinv @ As, pinv @ A))
        out["by_sensor"].append(np.linalg.norm(As - A, axis=1) / np.linalg.norm(A, axis=1))
        out["by_harmonic"].append(np.linalg.norm(As - A, axis=0) / np.linalg.norm(A))
    return {k: np.array(v) for k, v in out.items()}


CYCLE_PARTS = ("stick", "slip", "velocity_reversal", "peak_compression")


def _contact_gaps(
    model: IdentifiedModel, aug: Augmentation, rec: RecordHarmonics, sim, H: int, open_limit: float, memo: bool = True
):
    """Return one load case's contact-force stage.

    The contact forces identified from the record (inverse) against the laws at the identified motion, the inverse
    identification's residual and noise, the contact's open fraction, the energy per cycle (J; identified,
    simulated), the driving-point residual by part of the cycle and the force-state map of what the laws leave
    (``memo``: ``Numerics.memo``).
    """
    forces = identified_forces(model, aug, rec, memo=memo)
    g = contact_grids(forces, rec.f0, model.preload, 256)
    S_law = law_friction_force(g["xi"], g["xi_dot"], g["N"], np.asarray(model.friction), aug, model.regularization)[0]
    S_law -= S_law.mean()
    N_id = g["N"] - model.preload
    # the best elastic normal law at the identified motion (stiffness + hardening): what it leaves
    # is dissipation or opening in the normal direction
    A_el = np.column_stack([-g["eta"], g["eta"] ** 2 - np.mean(g["eta"] ** 2)])
    N_law = A_el @ np.linalg.lstsq(A_el, N_id, rcond=None)[0]
    T = 1.0 / rec.f0
    # part of the cycle: driving-point acceleration residual over one period
    r_t = periodic_grid(sim.acceleration[0, :H] - rec.acceleration[0, :H], rec.f0, 256)[0]
    a_rms = np.sqrt(np.mean(periodic_grid(rec.acceleration[0, :H], rec.f0, 256)[0] ** 2))
    parts = cycle_parts(g, model.structure.k_t)
    return {
        # the sensors' misfit of the inverse identification at the driven harmonics (1 and 3): the
        # structure and sensor model's consistency with the records, whatever the contact does
        "identification_residual": float(np.sqrt(np.mean(forces.residual[[0, 2]] ** 2))),
        "identification_noise": identification_noise(model, rec, memo),
        "S": relative_difference(S_law, g["S"]),
        "N": relative_difference(N_law, N_id),
        "open_fraction": open_fraction(g["N"], model.preload, open_limit),
        "energy_tangential": (float(np.mean(g["S"] * g["xi_dot"]) * T), sim.energy["tangential_j"]),
        "energy_normal": (float(-np.mean(N_id * g["eta_dot"]) * T), sim.energy["normal_j"]),
        "cycle_parts": [
            float(np.sqrt(np.mean(r_t[parts[p]] ** 2)) / a_rms) if parts[p].any() else 0.0 for p in CYCLE_PARTS
        ],
        "map": np.array([g["xi"], g["xi_dot"], g["S"] - S_law, g["eta"], g["eta_dot"], N_id - N_law]),
    }


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def localise(
    model: IdentifiedModel,
    records: dict[str, RecordHarmonics],
    sims: dict[str, SimResult],
    n_harmonics: int,
    linear: dict | None = None,
    aug: Augmentation = NONE,
    eta_limit: float = 0.1,
    structures: Sequence[StructureParameters] = (),
    thresholds: PlaceThresholds = DEFAULT_PLACE,
    memo: bool = True,
) -> tuple[dict, dict]:
    """Return the gap by stage, sensor, harmonic, part of the cycle and load level, and the place it lies in.

    The identified model is taken as the chain left it, or with the effects ``aug`` added; with the gap, the records'
    drift and whether each settled (``record_periodicity``), the inverse identification's residual and noise and
    how far the structures the data allow move eta.

    Parameters
    ----------
    model
        The identified model.
    records
        The load cases' records in harmonics, by case.
    sims
        The simulations of the records by the model (with ``aug``), by case.
    n_harmonics
        H, the harmonics compared.
    linear
        The random test's stage (``linear_stage``: frf_frequency, frf_peak_amplitude), added to the stages; None:
        none.
    aug
        The effects added to the model (``NONE``: as the chain left it).
    eta_limit
        The largest relative change of eta over ``structures`` for eta to count as observable (config
        ``gap.eta_observability_limit``) [-].
    structures
        The structures the data allow: the model's structure moved by one posterior standard deviation of each
        updated parameter (``updating.posterior_structures``); empty: none.
    thresholds
        The place's thresholds (config ``gap.place``).
    memo
        Whether the inverse identifications are memoised (``Numerics.memo``).

    Returns
    -------
    summary : dict
        For diagnosis.json's ``where``: stage (the gap of each stage), largest_stage, direction, by_sensor,
        worst_sensor, by_harmonic, worst_harmonic, even_share, harmonic_class, by_cycle_part, worst_cycle_part,
        by_load_case, load_exponent, drift {case: {change, z}}, periodicity, identification_residual,
        identification_noise, eta_observability, place and place_reason.
    arrays : dict
        For gap.nc: gap_by_sensor (n_cases, n_sensors), gap_by_harmonic (n_cases, H), gap_by_cycle_part
        (n_cases, 4), relative; energy_tangential and energy_normal (n_cases, 2: identified, simulated) in J;
        force_state_map (n_cases, 6, 256): xi, xi_dot, S - S_law, eta, eta_dot, N - N_law in SI units.
    """
    H = n_harmonics
    cases = list(records)
    resp = _response_gaps(fe_model(model, aug), records, sims, H)
    contact = [_contact_gaps(model, aug, records[c], sims[c], H, thresholds.open_limit, memo) for c in cases]
    per_case = {k: [row[k] for row in contact] for k in contact[0]}
    e_t, e_n = np.array(per_case["energy_tangential"]), np.array(per_case["energy_normal"])
    scale_e = np.abs(e_t[:, 0])
    stage = {
        "accelerations": _rms(resp["accelerations"]),
        "generalized_coordinates": _rms(resp["generalized_coordinates"]),
        "identification_residual": _rms(per_case["identification_residual"]),
        "open_fraction": float(np.max(per_case["open_fraction"])),
        "contact_force_S": _rms(per_case["S"]),
        "contact_force_N": _rms(per_case["N"]),
        "energy_tangential": _rms((e_t[:, 1] - e_t[:, 0]) / scale_e),
        "energy_normal": _rms((e_n[:, 1] - e_n[:, 0]) / scale_e),
    }
    if linear is not None:
        stage.update(linear)
    arrays = {
        "gap_by_sensor": resp["by_sensor"],
        "gap_by_harmonic": resp["by_harmonic"],
        "energy_tangential": e_t,
        "energy_normal": e_n,
        "gap_by_cycle_part": np.array(per_case["cycle_parts"]),
        "force_state_map": np.array(per_case["map"]),
    }
    summary = {"stage": stage, **_gap_patterns(stage, arrays, records, resp["accelerations"], thresholds)}
    summary["drift"] = {c: dict(zip(("change", "z"), record_drift(records[c], H))) for c in cases}
    summary["periodicity"] = record_periodicity(records, thresholds.aperiodic_limit)
    summary["identification_residual"] = dict(zip(cases, per_case["identification_residual"]))
    summary["identification_noise"] = dict(zip(cases, per_case["identification_noise"]))
    spread = {c: eta_model_spread(model, aug, records[c], structures, memo) for c in cases}
    finite = [v for v in spread.values() if np.isfinite(v)]
    worst = max(finite) if finite else float("nan")
    summary["eta_observability"] = {
        "model_spread": spread,
        "limit": eta_limit,
        "observable": bool(not finite or worst <= eta_limit),
    }
    summary["place"], summary["place_reason"] = _place_of(
        summary["drift"],
        stage,
        np.array(per_case["identification_residual"]),
        np.array(per_case["identification_noise"]),
        summary["eta_observability"]["observable"],
        worst,
        thresholds,
    )
    if not summary["eta_observability"]["observable"]:
        summary["direction"] = "unresolved"  # the normal direction's numbers rest on an unobservable eta
    return summary, arrays


def _gap_patterns(stage: dict, arrays: dict, records: dict, acc_gap, thresholds: PlaceThresholds) -> dict:
    """Return where the gap lies: the largest stage, the direction, by sensor, harmonic, part of the cycle, load case.

    The direction is normal when the normal contact force's gap exceeds ``thresholds.normal_limit`` or the contact
    opens; the harmonics are classed odd or even; the gap's growth with the load is the exponent of gap ~ A1^n over
    the load cases.
    """
    cases = list(records)
    ph = np.mean(arrays["gap_by_harmonic"] ** 2, axis=0)
    odd, even = float(np.sum(ph[0::2])), float(np.sum(ph[1::2]))
    part_mean = np.mean(arrays["gap_by_cycle_part"], axis=0)
    sensors = records[cases[0]].sensors
    by_sensor = np.mean(arrays["gap_by_sensor"] ** 2, axis=0)
    amps = [float(np.abs(records[c].acceleration[0, 0])) for c in cases]
    slope = (
        float(np.polyfit(np.log(amps), np.log(np.maximum(acc_gap, 1e-12)), 1)[0]) if len(cases) > 1 else float("nan")
    )
    largest = ("accelerations", "generalized_coordinates", "contact_force_S", "contact_force_N")
    largest += ("energy_tangential", "energy_normal")
    normal = stage["contact_force_N"] > thresholds.normal_limit or stage["open_fraction"] > 0
    return {
        "largest_stage": max(largest, key=lambda k: stage[k]),
        "direction": "normal" if normal else "tangential",
        "by_sensor": {s: float(v) for s, v in zip(sensors, np.sqrt(by_sensor))},
        "worst_sensor": sensors[int(np.argmax(by_sensor))],
        "by_harmonic": {int(h): float(np.sqrt(v)) for h, v in enumerate(ph, start=1)},
        "worst_harmonic": int(np.argmax(ph)) + 1,
        "even_share": even / max(odd + even, 1e-300),
        "harmonic_class": "even" if even > odd else "odd",
        "by_cycle_part": {p: float(v) for p, v in zip(CYCLE_PARTS, part_mean)},
        "worst_cycle_part": CYCLE_PARTS[int(np.argmax(part_mean))],
        "by_load_case": {c: float(g) for c, g in zip(cases, acc_gap)},
        "load_exponent": slope,
    }


def record_drift(rec: RecordHarmonics, H: int) -> tuple[float, float]:
    """Return the linear trend of the block harmonics over the record: its relative change and its size in errors.

    Parameters
    ----------
    rec
        One load case's record in harmonics.
    H
        The harmonics the trend is taken over (1..H).

    Returns
    -------
    change : float
        The trend's change over the record relative to the record's harmonics [-].
    z : float
        The trend's size in units of its own standard error from the scatter about the trend (about 1 for a
        stationary record) [-].
    """
    A = rec.block_acceleration[:, :, :H].reshape(rec.block_acceleration.shape[0], -1)
    b = np.arange(A.shape[0]) - 0.5 * (A.shape[0] - 1)
    slope = (b @ A) / (b @ b)
    resid = A - A.mean(axis=0) - np.outer(b, slope)
    sigma = np.sqrt(np.mean(np.sum(np.abs(resid) ** 2, axis=1)) * A.shape[0] / max(A.shape[0] - 2, 1))
    change = float(np.linalg.norm(slope) * (A.shape[0] - 1) / np.linalg.norm(rec.acceleration[:, :H]))
    return change, float(np.linalg.norm(slope) * np.sqrt(b @ b) / max(sigma, 1e-300))


def record_periodicity(records: Mapping[str, RecordHarmonics], limit: float) -> dict:
    """Return, per load case, the share of the response that is not periodic at the drive and whether it settled.

    The share is ``RecordHarmonics.aperiodic``'s, the worst accelerometer's and each one's; the record settled when
    that share is at most ``limit``. A record that does not settle (impacts, chaos) has harmonics that are averages
    of a motion that never repeats: the gap compares those averages, and a candidate, compared on harmonics, cannot
    be expected to explain it.

    Parameters
    ----------
    records
        The load cases' records in harmonics, by case (those without ``aperiodic`` are left out).
    limit
        The largest non-periodic share of a settled record (config ``gap.place.aperiodic_limit``) [-].

    Returns
    -------
    periodicity : dict
        {case: {aperiodic_share (the worst sensor's), by_sensor {sensor: share}, settled}}.
    """
    out = {}
    for c, rec in records.items():
        a = getattr(rec, "aperiodic", None)
        if a is None or not np.size(a):
            continue
        sensors = list(getattr(rec, "sensors", range(np.size(a))))
        worst = float(np.max(a))
        out[c] = {
            "aperiodic_share": worst,
            "by_sensor": {str(s): float(v) for s, v in zip(sensors, np.atleast_1d(a))},
            "settled": bool(worst <= limit),
        }
    return out


def identification_noise(model: IdentifiedModel, rec: RecordHarmonics, memo: bool = True) -> float:
    """Return the standard error of the inverse identification's sensor misfit (w and 3w) from the record's blocks.

    Parameters
    ----------
    model
        The identified model (as the chain left it, or a candidate's).
    rec
        One load case's record in harmonics.
    memo
        Whether the inverse identifications are memoised (``Numerics.memo``).

    Returns
    -------
    noise : float
        The standard error of the blocks' relative sensor misfit (rms over harmonics 1 and 3) [-].
    """
    import dataclasses

    r = []
    for k in range(rec.block_acceleration.shape[0]):
        blk = dataclasses.replace(rec, acceleration=rec.block_acceleration[k], force=rec.block_force[k])
        r.append(float(np.sqrt(np.mean(identified_forces(model, NONE, blk, memo=memo).residual[[0, 2]] ** 2))))
    return float(np.std(r) / np.sqrt(len(r)))


def eta_model_spread(
    model: IdentifiedModel,
    aug: Augmentation,
    rec: RecordHarmonics,
    structures: Sequence[StructureParameters],
    memo: bool = True,
) -> float:
    """Return how far the identified normal motion eta moves over the structures the data allow.

    The largest relative change (norm over the harmonics) of eta identified with each of ``structures`` against eta
    with the model's own. The k_t, k_n intervals alone (the chain's test) miss the structure's own uncertainty.

    Parameters
    ----------
    model
        The identified model (as the chain left it, or a candidate's).
    aug
        The effects added to the model (``NONE``: as the chain left it).
    rec
        One load case's record in harmonics.
    structures
        The structures the data allow: the model's structure moved by one posterior standard deviation of each
        updated parameter (``updating.posterior_structures``); empty: none.
    memo
        Whether the inverse identifications are memoised (``Numerics.memo``).

    Returns
    -------
    spread : float
        The largest relative change of eta [-]; NaN without structures.
    """
    import dataclasses

    if not structures:
        return float("nan")
    full = identified_forces(model, aug, rec, memo=memo).eta
    out = 0.0
    for p in structures:
        other = identified_forces(dataclasses.replace(model, structure=p), aug, rec, memo=memo).eta
        out = max(out, float(np.linalg.norm(other - full) / max(np.linalg.norm(full), 1e-300)))
    return out


# the place's thresholds (PlaceThresholds, config gap.place) and its logic live in place.py (pure functions,
# unit-tested in tests/gap/test_place.py)


def random_test_delays(frf: xr.Dataset, modal: xr.Dataset) -> np.ndarray | None:
    """Return each accelerometer channel's delay on the force from the random test's residue phases.

    The phases at its highest identified mode (``modal_fit.residue_phase_delays``).

    Parameters
    ----------
    frf
        The random test's FRFs (frf.nc): the ``frequency`` coordinate [Hz] and ``h1_real``, ``h1_imag`` [m/s^2/N]
        along (sensor, frequency), the driving point first.
    modal
        The modal fit's dataset (modal.nc): ``natural_frequency`` [Hz] and ``damping_ratio`` [-] along ``mode``,
        attributes ``band_low_hz`` and ``band_high_hz`` [Hz].

    Returns
    -------
    delays : np.ndarray | None
        Each sensor's delay on the force [s] (positive: late), shape (n_sensors,); None where the FRF or the modes do
        not allow it (logged) or a delay is not finite.
    """
    from ..linear_chain import complex_frf
    from ..modal_fit import residue_phase_delays

    try:
        H = complex_frf(frf)
        band = (float(modal.attrs["band_low_hz"]), float(modal.attrs["band_high_hz"]))
        tau = residue_phase_delays(
            frf["frequency"].values, H, modal["natural_frequency"].values, modal["damping_ratio"].values, band
        )
    except (KeyError, ValueError, np.linalg.LinAlgError) as exc:
        log.info("random test: no channel delays from the residue phases (%s)", exc)
        return None
    if not np.all(np.isfinite(tau)):
        return None
    log.info("random test: channel delays from the residue phases %s us", ", ".join(f"{1e6 * t:.2f}" for t in tau))
    return tau


def linear_stage(model: IdentifiedModel, frf: xr.Dataset, modal: xr.Dataset) -> dict:
    """Return the random test's FRF against the identified model: natural frequencies and peak accelerance.

    Parameters
    ----------
    model
        The identified model.
    frf
        The random test's FRFs (frf.nc): the ``frequency`` coordinate [Hz] and ``h1_real``, ``h1_imag`` [m/s^2/N]
        along (sensor, frequency), the driving point first.
    modal
        The modal fit's dataset (modal.nc): ``natural_frequency`` [Hz] and ``damping_ratio`` [-] along ``mode``.

    Returns
    -------
    stage : dict
        frf_frequency: the rms relative error of the model's structural natural frequencies against the identified
        ones; frf_peak_amplitude: the rms relative error of the model's driving-point accelerance against |H1| at the
        lines nearest the identified frequencies.
    """
    fe = fe_model(model)
    modes = all_modes(fe)
    zeta = modal_damping_vector(fe, np.asarray(model.damping))
    wn = 2 * np.pi * modes.frequencies_hz
    b = modes.shapes.T @ fe.force_vector
    d = fe.sensor_vectors[0] @ modes.shapes
    f_id = modal["natural_frequency"].values
    freq = frf["frequency"].values
    H1 = frf["h1_real"].values[0] + 1j * frf["h1_imag"].values[0]
    f_model = structural_modes(fe, len(f_id)).frequencies_hz
    peak_err = []
    for f in f_id:
        i = int(np.argmin(np.abs(freq - f)))
        W = 2 * np.pi * freq[i]
        Hm = -(W**2) * np.sum(d * b / (wn**2 - W**2 + 2j * zeta * wn * W))
        peak_err.append(abs(Hm) / abs(H1[i]) - 1)
    return {
        "frf_frequency": float(np.sqrt(np.mean((f_model / f_id - 1) ** 2))),
        "frf_peak_amplitude": float(np.sqrt(np.mean(np.square(peak_err)))),
    }


def place_left(
    last: tuple[Calibration, Mapping[str, SimResult | None]],
    records: Mapping[str, RecordHarmonics],
    calibration_case: str,
    H: int,
    linear: dict | None,
    structures: Sequence[StructureParameters],
    settings: GapSettings,
) -> dict | None:
    """Return the localisation of what the explanation leaves, with its effects in the model.

    Parameters
    ----------
    last
        The explanation's last step: its calibration (model, augmentation and the calibration case's simulation) and
        its held-out simulations by case.
    records
        The load cases' records in harmonics, by case.
    calibration_case
        The load case the step was calibrated on.
    H
        The harmonics compared.
    linear
        The random test's stage (``linear_stage``); None: none.
    structures
        The structures the data allow: the model's structure moved by one posterior standard deviation of each
        updated parameter (``updating.posterior_structures``); empty: none.
    settings
        The gap diagnosis's settings: eta_observability_limit, place and numerics.memo are read.

    Returns
    -------
    summary : dict | None
        ``localise``'s summary; None where a simulation is missing.
    """
    cal, sims = last
    all_sims = {c: (cal.simulation if c == calibration_case else sims[c]) for c in records}
    if any(s is None for s in all_sims.values()):
        return None
    where_left, _ = localise(
        cal.model,
        dict(records),
        all_sims,
        H,
        linear,
        aug=cal.augmentation,
        eta_limit=settings.eta_observability_limit,
        structures=structures,
        thresholds=settings.place,
        memo=settings.numerics.memo,
    )
    return where_left
