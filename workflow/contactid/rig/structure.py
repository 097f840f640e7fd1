"""The rig's structure: the configured structure with the rig's own changes and its true contact springs.

The configured structure takes ``rig.true_structure``'s changes where given (the rig's truth may differ from the
structure the identification assumes), and the contact springs are taken from the rig's true contact laws (their
small-amplitude limits).
"""

from __future__ import annotations

import copy
from typing import Mapping

from ..contact_laws import NormalLaw, ValanisParameters, stiction_shear_stiffness
from ..parameters import StructureParameters, structure_from_config
from .effects import effect_magnitudes


def deep_merge(base: Mapping, changes: Mapping | None) -> dict:
    """Return a copy of a mapping with changes applied key by key (nested mappings merged, the rest replaced).

    Parameters
    ----------
    base
        The mapping to change (left as it is: the result is a deep copy).
    changes
        The keys to change: a mapping value merged into a mapping of ``base`` at the same key, any other value
        replacing it; None or empty for none.

    Returns
    -------
    merged : dict
        A deep copy of ``base`` with ``changes`` applied.
    """
    out = copy.deepcopy(dict(base))
    for key, value in (changes or {}).items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def true_structure_config(structure_cfg: Mapping, rig_cfg: Mapping) -> dict:
    """Return the structure the rig simulates: ``structure`` with ``rig.true_structure`` merged in.

    ``rig.true_structure`` is any subset of the ``structure`` keys. The identification keeps ``structure``; raw
    records name the nominal sensors.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block.
    rig_cfg
        The config's ``rig`` block; its ``true_structure`` is read (absent or empty: no change).

    Returns
    -------
    structure : dict
        The ``structure`` block the rig simulates.
    """
    return deep_merge(structure_cfg, rig_cfg.get("true_structure") or {})


def rig_contact_stiffness(structure_cfg: Mapping, rig_cfg: Mapping) -> tuple[float, float]:
    """Return the rig's true contact stiffnesses: e_0 of Eq. 22 at the (true) preload, and the normal law's tangent.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block (its ``preload_n``, changed by ``rig.true_structure`` where that gives
        one).
    rig_cfg
        The config's ``rig`` block: its ``truth.friction`` (the true Valanis parameters) and ``truth.normal``
        (``stiffness_at_preload_n_per_m``, ``exponent``) are read, and ``true_structure``.

    Returns
    -------
    k_t : float
        Tangential stiffness at stiction, e_0 of Eq. 22 at the true preload [N/m].
    k_n : float
        The normal law's tangent stiffness at the true preload [N/m].
    """
    truth = rig_cfg["truth"]
    fr = ValanisParameters.from_config(truth["friction"])
    n0 = float(true_structure_config(structure_cfg, rig_cfg)["preload_n"])
    k_t = float(stiction_shear_stiffness(n0, fr.e_f, fr.k_c))
    k_n = NormalLaw(
        n0, float(truth["normal"]["stiffness_at_preload_n_per_m"]), float(truth["normal"]["exponent"])
    ).stiffness_at_preload
    return k_t, float(k_n)


def _rig_default(key: str):
    from ..schema import schema_defaults

    return schema_defaults("rig")[key]


def rig_structure(structure_cfg: Mapping, rig_cfg: Mapping) -> StructureParameters:
    """Return the StructureParameters of the rig: finer mesh, true structure and true contact stiffnesses.

    The effect transducer_mass_error (magnitude m) scales every transducer mass by 1 + m.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block.
    rig_cfg
        The config's ``rig`` block: ``true_structure``, ``truth`` (``rig_contact_stiffness``), ``fe_elements``
        (the schema's default where absent) and ``effects`` are read.

    Returns
    -------
    params : StructureParameters
        The structure the rig simulates.
    """
    k_t, k_n = rig_contact_stiffness(structure_cfg, rig_cfg)
    p = structure_from_config(
        true_structure_config(structure_cfg, rig_cfg),
        k_t,
        k_n,
        n_elements=int(rig_cfg.get("fe_elements", _rig_default("fe_elements"))),
    )
    m = effect_magnitudes(rig_cfg.get("effects"))["transducer_mass_error"]
    if m:
        p = p.replace(
            sensor_masses=tuple((1 + m) * x for x in p.sensor_masses),
            force_transducer_mass=(1 + m) * p.force_transducer_mass,
        )
    return p


def channel_delays(rig_cfg: Mapping, n_channels: int) -> tuple[float, ...] | None:
    """Return the per-accelerometer delays of the effect channel_time_skew, or None when it is off.

    With magnitude m (s), channel k of n is late by m (k + 1) / n.

    Parameters
    ----------
    rig_cfg
        The config's ``rig`` block; its ``effects.channel_time_skew`` is read.
    n_channels
        Number of accelerometer channels.

    Returns
    -------
    delays : tuple[float, ...] | None
        Each channel's delay relative to the force [s], n_channels of them; None where the effect is off.
    """
    m = effect_magnitudes(rig_cfg.get("effects"))["channel_time_skew"]
    if not m:
        return None
    return tuple(m * (k + 1) / n_channels for k in range(n_channels))


def channel_gains(rig_cfg: Mapping, n_channels: int) -> tuple[float, ...] | None:
    """Return the per-accelerometer sensitivity factors of the effect channel_gain_error, or None when it is off.

    With magnitude m, channel k of n reads 1 + m (-1)^k (k + 1) / n times its acceleration.

    Parameters
    ----------
    rig_cfg
        The config's ``rig`` block; its ``effects.channel_gain_error`` is read.
    n_channels
        Number of accelerometer channels.

    Returns
    -------
    gains : tuple[float, ...] | None
        Each channel's reading over its true acceleration [-], n_channels of them; None where the effect is off.
    """
    m = effect_magnitudes(rig_cfg.get("effects"))["channel_gain_error"]
    if not m:
        return None
    return tuple(1.0 + m * (-1) ** k * (k + 1) / n_channels for k in range(n_channels))


RANDOM_TEST_EFFECTS = ("transducer_mass_error", "channel_time_skew", "channel_gain_error")


def random_test_rig_config(rig_cfg: Mapping) -> dict:
    """Return the part of the ``rig`` config the random test depends on.

    Changing a dual-sine setting or a dual-sine-only effect then does not rerun the random test.

    Parameters
    ----------
    rig_cfg
        The config's ``rig`` block.

    Returns
    -------
    rig : dict
        ``rig_cfg`` without ``dual_sine``, its ``effects`` only those of ``RANDOM_TEST_EFFECTS``.
    """
    out = {k: v for k, v in rig_cfg.items() if k not in ("dual_sine", "effects")}
    out["effects"] = {k: v for k, v in (rig_cfg.get("effects") or {}).items() if k in RANDOM_TEST_EFFECTS}
    return out
