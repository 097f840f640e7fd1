"""The paper's own inconsistency: Table 1's frequencies against Table 3's stiffnesses and Table 4's e_0.

Each scenario (a candidate modelling assumption) fixes some quantities, fits others to Table 1 by least squares
on the relative frequency errors, and reports the model frequencies and their
errors. The finding this supports: the frequencies constrain the rotational
restraint a^2 k_t k_b / (k_t + k_b) at the tip, not k_t alone, so k_t follows
only once the tangential lever arm a (not given by the paper) is fixed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
import pandas as pd

from .beam_modes import natural_frequencies
from .contact_laws import ValanisParameters, stiction_shear_stiffness
from .parameters import StructureParameters, structure_from_config

TABLE1_HZ = np.array([54.85, 166.2, 339.25])  # paper, Table 1
TABLE3 = {"k_t": 3.95e6, "k_n": 2.37e7}  # paper, Table 3 (N/m)
TABLE4 = {"e_f": 3.857e7, "k_c": 2.547e5, "e_t": 0.0, "kappa": 0.284, "mu": 0.397}  # paper, Table 4


@dataclass(frozen=True)
class Scenario:
    """A modelling assumption to test against Table 1.

    Attributes
    ----------
    name
        Its label (a letter in the table).
    description
        What it assumes, in words.
    fixed
        The ``StructureParameters`` fields it fixes: name -> value, in the field's unit.
    free
        The names of the ``StructureParameters`` fields it fits (log-scaled where positive and wide).
    """

    name: str
    description: str
    fixed: dict
    free: tuple  # names of StructureParameters fields fitted (log-scaled where positive and wide)


LOG_FIELDS = {"k_t", "k_n", "youngs_modulus", "clamp_rotational_stiffness"}


def fit_scenario(
    base: StructureParameters, scenario: Scenario, target_hz: np.ndarray = TABLE1_HZ
) -> tuple[dict[str, float], np.ndarray]:
    """Fit the scenario's free quantities to the target frequencies.

    Least squares on the relative frequency errors, the fields of ``LOG_FIELDS`` in log10, the others bounded below
    by zero (masses and lengths stay non-negative).

    Parameters
    ----------
    base
        The structure the scenario's fixed values are put into.
    scenario
        The assumption: which fields it fixes and which it fits.
    target_hz
        Natural frequencies to fit [Hz], lowest first, shape (n_freq,); by default the paper's Table 1.

    Returns
    -------
    values : dict[str, float]
        The fitted fields, name -> value in the field's own unit [units of StructureParameters] (N/m for k_t, Pa for
        youngs_modulus, m for a length, ...); empty where the scenario fits nothing.
    frequencies : np.ndarray
        The model's natural frequencies with those values [Hz], shape (n_freq,).
    """
    p0 = base.replace(**scenario.fixed)
    names = scenario.free
    if not names:
        return {}, natural_frequencies(p0, len(target_hz))

    def build(x):
        ch = {n: (10.0**v if n in LOG_FIELDS else v) for n, v in zip(names, x)}
        return p0.replace(**ch), ch

    x0 = [np.log10(getattr(p0, n)) if n in LOG_FIELDS else getattr(p0, n) for n in names]
    lower = [-np.inf if n in LOG_FIELDS else 0.0 for n in names]  # masses, lengths stay non-negative
    from scipy.optimize import least_squares  # here: the report's figures import this module's tables

    r = least_squares(
        lambda x: natural_frequencies(build(x)[0], len(target_hz)) / target_hz - 1.0,
        x0,
        bounds=(lower, np.inf),
        x_scale="jac",
        xtol=1e-12,
        ftol=1e-12,
    )
    p, ch = build(r.x)
    return ch, natural_frequencies(p, len(target_hz))


def paper_consistency_table(
    structure_cfg: Mapping[str, Any], friction_truth: Mapping[str, Any] | None = None
) -> pd.DataFrame:
    """Return Table 1 against Table 3 / Table 4 under candidate assumptions.

    The base model is the configured structure with the paper's nominal
    assumptions: tangential lever arm a = r and E = 210 GPa. With ``friction_truth``, a last row gives the configured
    structure itself with the rig's k_t = e_0(N0) (the rig's default truth).

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` mapping (as for ``parameters.structure_from_config``), with ``preload_n``.
    friction_truth
        The rig truth's friction law (``rig.truth.friction``: ``e_f_n_per_m``, ``k_c_per_m``, ``e_t_n_per_m``,
        ``kappa``, ``mu``), or None for no ``config`` row.

    Returns
    -------
    table : pd.DataFrame
        One row per scenario: ``scenario``, ``assumption``, ``fitted`` (the fitted values in words), ``k_t_n_per_m``,
        ``k_n_n_per_m``, ``tangential_lever_arm_m``, ``youngs_modulus_pa``, ``rotational_restraint_nm_per_rad``,
        the model frequencies ``f1_hz``..``f3_hz``, their errors against Table 1 ``err1_pct``..``err3_pct`` and
        ``max_abs_err_pct`` (in %).
    """
    cfg_params = structure_from_config(structure_cfg, TABLE3["k_t"], TABLE3["k_n"])
    base = cfg_params.replace(tangential_lever_arm=cfg_params.pin_radius, youngs_modulus=2.1e11)
    n0 = float(structure_cfg["preload_n"])
    e0_paper = float(stiction_shear_stiffness(n0, TABLE4["e_f"], TABLE4["k_c"]))
    r, h = base.pin_radius, base.thickness
    t3 = dict(TABLE3)
    e0 = {"k_t": e0_paper, "k_n": TABLE3["k_n"]}
    scenarios = [
        Scenario("A", "Table 3 k_t, k_n; a = r, E = 210 GPa (paper as printed)", t3, ()),
        Scenario("B", "k_t fitted to Table 1; a = r, E = 210 GPa", {"k_n": TABLE3["k_n"]}, ("k_t",)),
        Scenario("C", "k_t and k_n fitted to Table 1; a = r, E = 210 GPa", {}, ("k_t", "k_n")),
        Scenario("D", "Table 3; E fitted", t3, ("youngs_modulus",)),
        Scenario("E", "Table 3; thickness fitted", t3, ("thickness",)),
        Scenario("F", "Table 3; transducer masses scaled (force transducer fitted)", t3, ("force_transducer_mass",)),
        Scenario(
            "G",
            "Table 3; clamp rotational compliance fitted",
            {**t3, "clamp_rotational_stiffness": 1e6},
            ("clamp_rotational_stiffness",),
        ),
        Scenario("H", "Table 3; tangential lever arm a fitted", t3, ("tangential_lever_arm",)),
        Scenario("I", "Table 3; a = r + h/2", {**t3, "tangential_lever_arm": r + h / 2}, ()),
        Scenario("J", "Table 3; a and E fitted", t3, ("tangential_lever_arm", "youngs_modulus")),
        Scenario("K", "k_t = e_0(N0) of Table 4; a = r, E = 210 GPa", e0, ()),
        Scenario("L", "k_t = e_0(N0) of Table 4; E fitted", e0, ("youngs_modulus",)),
        Scenario("M", "k_t = e_0(N0) of Table 4; a fitted", e0, ("tangential_lever_arm",)),
        Scenario("N", "k_t = e_0(N0) of Table 4; a and E fitted", e0, ("tangential_lever_arm", "youngs_modulus")),
    ]
    rows = []
    for sc in scenarios:
        ch, f = fit_scenario(base, sc)
        rows.append(_row(sc.name, sc.description, ch, base.replace(**{**sc.fixed, **ch}), f))
    # the configured structure itself (the rig's default truth uses it with e_0 at the preload)
    if friction_truth:
        fr = ValanisParameters.from_config(friction_truth)
        p = cfg_params.with_contact(float(stiction_shear_stiffness(n0, fr.e_f, fr.k_c)), TABLE3["k_n"])
        rows.append(
            _row(
                "config",
                "configured structure with the rig's k_t = e_0(N0) (the rig's default truth)",
                {},
                p,
                natural_frequencies(p, 3),
            )
        )
    return pd.DataFrame(rows)


def _row(name: str, description: str, fitted: Mapping, p: StructureParameters, f: np.ndarray) -> dict:
    err = 100.0 * (f / TABLE1_HZ - 1.0)
    return {
        "scenario": name,
        "assumption": description,
        "fitted": "; ".join(f"{k}={v:.4g}" for k, v in fitted.items()) or "-",
        "k_t_n_per_m": p.k_t,
        "k_n_n_per_m": p.k_n,
        "tangential_lever_arm_m": p.tangential_lever_arm,
        "youngs_modulus_pa": p.youngs_modulus,
        "rotational_restraint_nm_per_rad": p.tangential_lever_arm**2
        * p.k_t
        * p.axial_stiffness
        / (p.k_t + p.axial_stiffness),
        "f1_hz": f[0],
        "f2_hz": f[1],
        "f3_hz": f[2],
        "err1_pct": err[0],
        "err2_pct": err[1],
        "err3_pct": err[2],
        "max_abs_err_pct": float(np.max(np.abs(err))),
    }
