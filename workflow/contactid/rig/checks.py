"""Checks on the virtual rig itself.

Time-step and mode-count convergence, agreement with the linear FRF at low level, and the change each unmodelled
effect makes.
"""

from __future__ import annotations

import copy
from typing import Mapping

import numpy as np
import pandas as pd

from ..beam_model import assemble
from ..beam_modes import all_modes
from ..harmonics import harmonic_amplitudes
from .control import control_response
from .damping import dual_sine_damping_ratios
from .dual_sine import build_simulator, dual_sine_settings, dual_sine_test
from .effects import EFFECTS
from .structure import rig_structure


def _steady_harmonics(sim, F1, F3, w, harmonics=(1, 2, 3, 4, 5)):
    sim.start_from_linear(F1, F3, w)
    sim.settle(F1, F3, w, tol=1e-6, min_chunks=4)
    n = int(round(16 * 2 * np.pi / w / sim.dt))
    out = sim.run(F1, F3, w, n, store_from=0)
    return harmonic_amplitudes(out["a"] @ sim.red.drive, out["t"], w, harmonics)


def convergence_study(
    structure_cfg: Mapping, rig_cfg: Mapping, case_cfg: Mapping, sampling_rate_hz: float
) -> pd.DataFrame:
    """Return the time-step and mode-count convergence of the driving-point harmonics.

    Driving-point harmonics 1-5 at the controlled force of ``case_cfg`` for the default model, half the time step, and
    twice the retained modes; relative changes (%).

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block.
    rig_cfg
        The config's ``rig`` block (``dual_sine``, ``truth``, ``effects``, damping, ...).
    case_cfg
        The load case: its target driving-point amplitudes ``A1_m_per_s2`` and ``A2_m_per_s2`` at w and 3w [m/s^2],
        and optionally ``excitation_frequency_hz``.
    sampling_rate_hz
        The records' sampling rate [Hz].

    Returns
    -------
    study : pd.DataFrame
        One row per variant ("half time step", "double modes") and harmonic: ``amplitude_m_per_s2`` (the default
        model's, m/s^2) and ``change_pct`` (the variant's relative change, %).
    """
    s = dual_sine_settings(rig_cfg, case_cfg, sampling_rate_hz)
    w = 2 * np.pi * s["excitation_frequency_hz"]
    sim = build_simulator(structure_cfg, rig_cfg, s)
    ctl = control_response(sim, float(case_cfg["A1_m_per_s2"]), float(case_cfg["A2_m_per_s2"]), w)
    base = _steady_harmonics(sim, ctl.F1, ctl.F3, w)
    rows = []
    for name, kw in (
        ("half time step", {"oversampling": 2 * int(s["oversampling"])}),
        ("double modes", {"n_modes": 2 * int(s["n_modes"])}),
    ):
        other = _steady_harmonics(build_simulator(structure_cfg, rig_cfg, s, **kw), ctl.F1, ctl.F3, w)
        for h, (a, b) in enumerate(zip(base, other), start=1):
            rows.append(
                {"variant": name, "harmonic": h, "amplitude_m_per_s2": abs(a), "change_pct": 100 * abs(b - a) / abs(a)}
            )
    return pd.DataFrame(rows)


def low_level_frf_check(
    structure_cfg: Mapping, rig_cfg: Mapping, sampling_rate_hz: float, frequency_hz: float = 54.4, level: float = 0.02
) -> pd.DataFrame:
    """Compare a dual-sine test at a low level (the contact sticks) with the full FE model's linear accelerance.

    The FE model's is the stuck linear driving-point accelerance at f and 3f (with the rig's modal damping).

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block.
    rig_cfg
        The config's ``rig`` block.
    sampling_rate_hz
        The records' sampling rate [Hz].
    frequency_hz
        The excitation frequency f [Hz] (moved to a whole number of periods in the record).
    level
        The target driving-point amplitude at f [m/s^2]; at 3f it is 2.5 times as much.

    Returns
    -------
    check : pd.DataFrame
        One row per harmonic (1 and 3): ``frequency_hz`` (Hz), the rig's and the FE model's accelerance magnitudes
        ``rig_accelerance`` and ``fe_accelerance`` ((m/s^2)/N) and ``difference_pct`` (%).
    """
    case = {"A1_m_per_s2": level, "A2_m_per_s2": 2.5 * level, "excitation_frequency_hz": frequency_hz}
    s = dual_sine_settings(rig_cfg, case, sampling_rate_hz)
    w = 2 * np.pi * s["excitation_frequency_hz"]
    sim = build_simulator(structure_cfg, rig_cfg, s)
    ctl = control_response(sim, case["A1_m_per_s2"], case["A2_m_per_s2"], w)
    model = assemble(rig_structure(structure_cfg, rig_cfg))
    modes = all_modes(model)
    zeta = dual_sine_damping_ratios(rig_cfg, modes.frequencies_hz)
    wn = 2 * np.pi * modes.frequencies_hz
    b = modes.shapes.T @ model.force_vector
    rows = []
    for h, F, A in ((1, ctl.F1, ctl.A1), (3, ctl.F3, ctl.A3)):
        W = h * w
        H = -(W**2) * np.sum(b * b / (wn**2 - W**2 + 2j * zeta * wn * W))
        rows.append(
            {
                "harmonic": h,
                "frequency_hz": W / (2 * np.pi),
                "rig_accelerance": A / F,
                "fe_accelerance": abs(H),
                "difference_pct": 100 * (A / F / abs(H) - 1),
            }
        )
    return pd.DataFrame(rows)


def effect_study(
    structure_cfg: Mapping,
    rig_cfg: Mapping,
    case_cfg: Mapping,
    sampling_rate_hz: float,
    magnitudes: Mapping | None = None,
    seed: int = 0,
) -> pd.DataFrame:
    """Return the change each unmodelled effect makes, alone, against the baseline.

    Each effect runs alone at its typical magnitude (or ``magnitudes``), noise-free: change of the force amplitudes
    and NRMSE (%) of the recorded driving-point acceleration and force.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block (``sensors.names`` is read too).
    rig_cfg
        The config's ``rig`` block; its ``effects`` are replaced by each effect in turn.
    case_cfg
        The load case (``A1_m_per_s2``, ``A2_m_per_s2``, optionally ``excitation_frequency_hz``).
    sampling_rate_hz
        The records' sampling rate [Hz].
    magnitudes
        {effect: magnitude} in each effect's unit (``EFFECTS``); effects left out: their typical magnitude.
    seed
        The random seed of the tests.

    Returns
    -------
    study : pd.DataFrame
        One row per effect: ``magnitude`` and its ``unit``, ``F1_change_pct`` and ``F3_change_pct`` (%),
        ``drive_acceleration_nrmse_pct`` and ``force_nrmse_pct`` (%) and ``min_normal_force_n`` (N).
    """

    def run(effects):
        rc = copy.deepcopy(dict(rig_cfg))
        rc["effects"] = effects
        raw, truth = dual_sine_test(
            structure_cfg, rc, case_cfg, sampling_rate_hz, 0.0, seed, "effect_study", structure_cfg["sensors"]["names"]
        )
        return raw, truth

    raw0, tr0 = run({})
    a0, f0 = raw0["acceleration"].values[0], raw0["force"].values

    def nrmse(x, ref):
        return 100 * np.sqrt(np.mean((x - ref) ** 2)) / np.sqrt(np.mean((ref - ref.mean()) ** 2))

    rows = []
    for name, spec in EFFECTS.items():
        mag = float((magnitudes or {}).get(name, spec.typical))
        raw, tr = run({name: mag})
        rows.append(
            {
                "effect": name,
                "magnitude": mag,
                "unit": spec.unit,
                "F1_change_pct": 100 * (tr.attrs["F1_n"] / tr0.attrs["F1_n"] - 1),
                "F3_change_pct": 100 * (tr.attrs["F3_n"] / tr0.attrs["F3_n"] - 1),
                "drive_acceleration_nrmse_pct": nrmse(raw["acceleration"].values[0], a0),
                "force_nrmse_pct": nrmse(raw["force"].values, f0),
                "min_normal_force_n": float(tr["N"].min()),
            }
        )
    return pd.DataFrame(rows)
