"""The rig's true damping: its form may differ from the identified model's modal damping.

``rig.modal_damping_ratio`` is the damping ratio at ``rig.true_damping.reference_frequency_hz``;
``rig.true_damping.form`` spreads it over the modes (and the reduced model's static contact shapes):

- ``modal``: every mode the same ratio (the identified model's form);
- ``stiffness_proportional``: C = beta K, zeta_i = zeta_ref f_i / f_ref (grows with frequency, so the
  static contact shapes, high in frequency, are damped most);
- ``mass_proportional``: C = alpha M, zeta_i = zeta_ref f_ref / f_i;
- ``rayleigh``: C = alpha M + beta K with both terms equal at f_ref, zeta_i = zeta_ref (f_ref / f_i + f_i / f_ref) / 2
  (as FE simulators often damp: least at f_ref, growing as f above it).

Ratios are kept within [MIN_FRACTION zeta_ref, MAX_RATIO].

``rig.true_damping.dual_sine_factor`` scales every ratio in the dual-sine tests against the random test's: a
structure whose damping changes with the level and with the contact slipping (1: the same in both tests, the
identified model's assumption).
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

FORMS = ("modal", "stiffness_proportional", "mass_proportional", "rayleigh")
MAX_RATIO = 2.0  # ratios are capped (an overdamped static shape stays overdamped)
MIN_FRACTION = 0.2  # ... and floored at this fraction of the reference ratio: mass-proportional damping alone
# leaves the kHz static normal shape with zeta ~ 1e-4, and with a hardening normal law the explicit integrator's
# response then blew up (compound benchmark item with masses -39 %, k_3 = 4.4e19 N/m^3); real structures keep
# some damping up there


def damping_ratios(
    frequencies_hz: np.ndarray, ratio: float, form: str = "modal", reference_hz: float = 54.4
) -> np.ndarray:
    """Return the damping ratio of each mode for a damping form.

    The forms are the module's; the ratios are kept within [MIN_FRACTION ratio, MAX_RATIO].

    Parameters
    ----------
    frequencies_hz
        Undamped natural frequency f_i of each mode [Hz], shape (n_modes,) (any shape: the result has it).
    ratio
        Damping ratio at the reference frequency, zeta_ref [-].
    form
        The damping form, one of ``FORMS``.
    reference_hz
        Reference frequency f_ref at which the ratio holds [Hz].

    Returns
    -------
    ratios : np.ndarray
        Damping ratio zeta_i of each mode [-], shape (n_modes,) (that of ``frequencies_hz``).

    Raises
    ------
    ValueError
        When ``form`` is not one of ``FORMS``.
    """
    f = np.asarray(frequencies_hz, dtype=float)
    if form == "modal":
        z = np.full(f.shape, float(ratio))
    elif form == "stiffness_proportional":
        z = float(ratio) * f / float(reference_hz)
    elif form == "mass_proportional":
        z = float(ratio) * float(reference_hz) / np.maximum(f, 1e-9)
    elif form == "rayleigh":
        x = np.maximum(f, 1e-9) / float(reference_hz)
        z = 0.5 * float(ratio) * (1.0 / x + x)
    else:
        raise ValueError(f"rig.true_damping.form = {form!r} is not one of {FORMS}")
    return np.clip(z, MIN_FRACTION * float(ratio), MAX_RATIO)


def rig_damping_ratios(rig_cfg: Mapping, frequencies_hz: np.ndarray) -> np.ndarray:
    """Return the rig's damping ratio of each mode: rig.modal_damping_ratio spread by rig.true_damping.

    Keys ``rig_cfg`` leaves out take the schema's defaults.

    Parameters
    ----------
    rig_cfg
        The config's ``rig`` block: reads ``modal_damping_ratio`` and ``true_damping`` (``form``,
        ``reference_frequency_hz``).
    frequencies_hz
        Undamped natural frequency of each mode [Hz], shape (n_modes,).

    Returns
    -------
    ratios : np.ndarray
        Damping ratio of each mode [-], shape (n_modes,).
    """
    from ..schema import schema_defaults

    defaults = schema_defaults("rig")  # where rig_cfg leaves keys out
    td = {**defaults["true_damping"], **(rig_cfg.get("true_damping") or {})}
    ratio = rig_cfg.get("modal_damping_ratio", defaults["modal_damping_ratio"])
    return damping_ratios(frequencies_hz, float(ratio), td["form"], float(td["reference_frequency_hz"]))


def dual_sine_damping_ratios(rig_cfg: Mapping, frequencies_hz: np.ndarray) -> np.ndarray:
    """Return the rig's damping ratio of each mode in the dual-sine tests.

    ``rig_damping_ratios`` times rig.true_damping.dual_sine_factor.

    Parameters
    ----------
    rig_cfg
        The config's ``rig`` block: reads ``modal_damping_ratio`` and ``true_damping`` (``form``,
        ``reference_frequency_hz``, ``dual_sine_factor``).
    frequencies_hz
        Undamped natural frequency of each mode [Hz], shape (n_modes,).

    Returns
    -------
    ratios : np.ndarray
        Damping ratio of each mode in the dual-sine tests [-], shape (n_modes,).
    """
    from ..schema import schema_defaults

    td = {**schema_defaults("rig")["true_damping"], **(rig_cfg.get("true_damping") or {})}
    return rig_damping_ratios(rig_cfg, frequencies_hz) * float(td["dual_sine_factor"])
