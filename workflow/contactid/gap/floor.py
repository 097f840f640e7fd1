"""Measure the identification's own floor of the held-out gap on the virtual rig at the records' drive.

``gap.min_gap`` is the held-out gap below which the diagnosis explains nothing: what the chain's own identification
leaves on records without any unmodelled effect. That floor depends on the drive: 0.30 % on the default data at 54.4 Hz
(the value 0.006 was set as about twice it), 0.05 % at 60 Hz, where a viscous friction of 300 N s/m raised the held-out
gap to 0.46 % and stayed below the fixed floor (docs/measurements.md, "The floor measured at the records' drive").

``gap.measure_floor`` (true by default) measures it: the rig, with no effect, its nominal structure and damping (none of
``rig.true_structure``, ``rig.true_damping``, nor a cubic normal law) and the identified friction law as its truth, is
driven at the calibration record's frequency, sampling rate and length and at the load cases' response levels (the
configured ones; a measured case's read from its record, ``response_targets``; seeded by the config's seed); the chain
identifies the model from those records (random test, linear chain, the friction law's fit on the calibration case) and
the identified model's held-out gap on the other cases is the floor. ``min_gap`` is then ``FLOOR_FACTOR`` times it.
Where there is no held-out case (one load case), nothing is measured and ``gap.min_gap`` stands.
"""

from __future__ import annotations

import copy
import json
import logging
import time
from typing import TYPE_CHECKING, Any, Mapping, Sequence

from ..friction_parameters import PARAMETER_NAMES

if TYPE_CHECKING:
    import xarray as xr

log = logging.getLogger(__name__)

# min_gap = FLOOR_FACTOR x the floor: the fixed default 0.006 was set at about twice the default data's 0.30 %
FLOOR_FACTOR = 2.0

_TRUTH_KEYS = {
    "e_f": "e_f_n_per_m",
    "k_c": "k_c_per_m",
    "e_t": "e_t_n_per_m",
    "kappa": "kappa",
    "mu": "mu",
}


def floor_rig_config(
    cfg: Mapping, friction: Sequence[float], regularization: str, f0: float, fs: float, n_samples: int
) -> dict:
    """Return the config of the floor's rig.

    ``cfg`` (with the schema's defaults) with the rig's effects, true structure, true damping and cubic normal term
    removed, the friction law ``friction`` with ``regularization`` as its truth, and the dual-sine drive at ``f0``,
    sampled at ``fs`` for ``n_samples`` samples (the calibration record's).

    Parameters
    ----------
    cfg
        The configuration; its ``rig`` block (effects, true_structure, true_damping, truth.normal, truth.friction,
        dual_sine) and ``random_test`` block (sampling_rate_hz, source) are changed in a copy.
    friction
        The identified law e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -].
    regularization
        How the rig reads Eq. 21: ``none`` or ``slip_limit``.
    f0
        The drive (excitation) frequency [Hz].
    fs
        The sampling rate [Hz].
    n_samples
        Samples per dual-sine record.

    Returns
    -------
    config : dict
        The floor rig's config, with the schema's defaults.
    """
    from ..schema import with_defaults

    out = copy.deepcopy(dict(with_defaults(cfg)))
    rig = out["rig"]
    rig["effects"] = {}
    rig.pop("true_structure", None)
    rig.pop("true_damping", None)
    rig["truth"]["normal"].pop("cubic_n_per_m3", None)
    law = dict(zip(PARAMETER_NAMES, (float(x) for x in friction)))
    rig["truth"]["friction"] = {
        **{_TRUTH_KEYS[k]: law[k] for k in _TRUTH_KEYS},
        "regularization": str(regularization),
    }
    rig["dual_sine"]["excitation_frequency_hz"] = float(f0)
    rig["dual_sine"]["record_samples"] = int(n_samples)
    out["random_test"]["sampling_rate_hz"] = float(fs)
    out["random_test"]["source"] = "rig"
    return with_defaults(out)


def response_targets(
    raw: xr.Dataset, positions: Sequence[float], excitation_position: float, n_harmonics: int = 3
) -> dict:
    """Return a load case's response levels as the rig's response control takes them.

    {"A1_m_per_s2", "A2_m_per_s2"}: the driving point's acceleration amplitudes at w and 3w, read from a dual-sine
    record at the sensor nearest the excitation: a measured case's levels, which its config block does not give.

    Parameters
    ----------
    raw
        The dual-sine record (force and accelerations, with its sampling and excitation frequencies).
    positions
        The sensors' positions along the beam [m], one per sensor.
    excitation_position
        The excitation's position along the beam [m].
    n_harmonics
        Harmonics to take (at least 3 are).

    Returns
    -------
    targets : dict
        {"A1_m_per_s2": amplitude at w, "A2_m_per_s2": amplitude at 3w} [m/s^2].
    """
    import numpy as np

    from .records import record_harmonics

    rec = record_harmonics(raw, "record", max(3, int(n_harmonics)))
    s = int(np.argmin(np.abs(np.asarray(positions, dtype=float) - float(excitation_position))))
    return {"A1_m_per_s2": float(abs(rec.acceleration[s, 0])), "A2_m_per_s2": float(abs(rec.acceleration[s, 2]))}


def identification_floor(
    cfg: Mapping, friction: Sequence[float], regularization: str, f0: float, fs: float, n_samples: int, seed: int
) -> dict:
    """Return the held-out gap the chain's own identification leaves at this drive (see the module's docstring).

    Parameters
    ----------
    cfg
        The configuration (its load cases, nonlinear.calibration_case, nonlinear.n_harmonics, gap.n_harmonics, rig).
    friction
        The identified law e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], the floor rig's truth.
    regularization
        How the rig reads Eq. 21: ``none`` or ``slip_limit``.
    f0
        The calibration record's drive frequency [Hz].
    fs
        The calibration record's sampling rate [Hz].
    n_samples
        The calibration record's samples.
    seed
        Seed of the rig's records.

    Returns
    -------
    floor : dict
        {"floor", "min_gap", "factor", "by_case", "drive_hz", "sampling_rate_hz", "record_samples", "calibration_case",
        "control_converged", "seconds"}: the floor and min_gap relative [-], drive and rate [Hz], time [s]; where no
        load case is held out, {"floor": None, "min_gap": None, "reason"}.
    """
    from .evidence import heldout_gap_of
    from .pipeline import identify, rig_records
    from .records import record_harmonics
    from .refit import baseline

    t0 = time.perf_counter()
    rig_cfg = floor_rig_config(cfg, friction, regularization, f0, fs, n_samples)
    cases = list(rig_cfg["load_cases"])
    cal = rig_cfg["nonlinear"]["calibration_case"]
    held = [c for c in cases if c != cal]
    if not held:  # nothing to hold out: no floor to measure, gap.min_gap stands
        log.info("floor: no load case besides the calibration case %s; gap.min_gap as configured", cal)
        return {"floor": None, "min_gap": None, "reason": f"no load case besides the calibration case {cal}"}
    log.info(
        "floor: the rig without effects at %.4g Hz (%d samples at %.6g Hz), the identified law as its truth; "
        "making the records of %s",
        f0,
        n_samples,
        fs,
        ", ".join(["random_test", *cases]),
    )
    recs, converged = rig_records(rig_cfg, {}, int(seed), cases)
    model = identify(rig_cfg, recs["random_test"], recs[cal])[0]
    H = int(rig_cfg["gap"]["n_harmonics"])
    K = int(rig_cfg["nonlinear"]["n_harmonics"])
    records = {c: record_harmonics(recs[c], c, K) for c in held}
    sims = {c: baseline(model, records[c], H)[1] for c in held}
    by_case = {c: heldout_gap_of(records, [c], H, sims) for c in held}
    floor = heldout_gap_of(records, held, H, sims)
    seconds = time.perf_counter() - t0
    log.info(
        "floor: the identified model's held-out gap on the rig without effects %.4g %% (%s); gap.min_gap = %g x it "
        "= %.4g %% (%.1f s)",
        100 * floor,
        ", ".join(f"{c} {100 * g:.3g} %" for c, g in by_case.items()),
        FLOOR_FACTOR,
        100 * FLOOR_FACTOR * floor,
        seconds,
    )
    return {
        "floor": float(floor),
        "min_gap": float(FLOOR_FACTOR * floor),
        "factor": FLOOR_FACTOR,
        "by_case": {c: float(g) for c, g in by_case.items()},
        "drive_hz": float(f0),
        "sampling_rate_hz": float(fs),
        "record_samples": int(n_samples),
        "calibration_case": cal,
        "control_converged": {c: int(v) for c, v in converged.items()},
        "seconds": float(seconds),
    }


def read_floor(inputs: Any) -> dict | None:
    """Return the measured floor a rule was given, or None where gap.measure_floor is off.

    Parameters
    ----------
    inputs
        The rule's ``snakemake.input``; its ``floor`` (results/gap/floor.json or the benchmark's), where present, is
        read.

    Returns
    -------
    floor : dict | None
        ``identification_floor``'s result as written, or None without a ``floor`` input.
    """
    return json.loads(open(inputs.floor).read()) if "floor" in inputs.keys() else None


def resolved_gap_config(gap: Mapping, floor: Mapping | None) -> dict:
    """Return the gap settings with ``min_gap`` the measured floor's where one was measured, else ``gap``'s own.

    Parameters
    ----------
    gap
        The ``gap`` config block.
    floor
        ``identification_floor``'s result (results/gap/floor.json); None: not measured.

    Returns
    -------
    gap : dict
        A copy of ``gap`` with ``min_gap`` replaced where the floor was measured.
    """
    out = dict(gap)
    if floor is not None and floor.get("min_gap") is not None:
        out["min_gap"] = float(floor["min_gap"])
    return out
