"""Items of the blind benchmark (config ``gap_benchmark``).

The effects' benchmark ranges and where the localisation should point when an effect is missing from the library, the
blind, effect-free, leave-out and ladder items, the compound items (a perturbed rig with 0, 1 or 2 effects) and their
rigs' configs, what an item hides and its expected run time.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

from ..random_streams import generator
from ..rig.effects import EFFECTS
from ..schema import schema_defaults

# magnitudes the benchmark draws from (rig units, see rig.effects): large enough to matter,
# within the range where the rig's response stays periodic
RANGES = {
    "structural_damping": (0.002, 0.01),
    "normal_contact_damping": (150.0, 600.0),
    "viscous_friction": (150.0, 600.0),
    "multi_asperity_friction": (0.5, 1.0),
    "transducer_mass_error": (0.15, 0.5),
    "channel_time_skew": (1.0e-5, 4.0e-5),
    "channel_gain_error": (0.015, 0.05),  # channels 0.5-5 % off: a calibration's tolerance
    "contact_separation": (5.05, 5.2),  # lc3 (1.43 x lc1) separates; above, its motion stops settling
    "preload_drift": (0.05, 0.2),
}

# where the localisation should point when the effect is missing from the library
EXPECTED_PLACE = {
    "structural_damping": "structure_or_measurement",
    "transducer_mass_error": "structure_or_measurement",
    "channel_time_skew": "structure_or_measurement",
    "channel_gain_error": "structure_or_measurement",
    "normal_contact_damping": "normal_contact",
    "contact_separation": "normal_contact",
    "viscous_friction": "tangential_contact",
    "multi_asperity_friction": "tangential_contact",
    "preload_drift": "non_stationary",
}


def benchmark_items(cfg: Mapping, seed: int) -> dict:
    """Return the blind benchmark's items: blind, effect-free, leave-out and compound ones.

    Each blind item puts one effect at a magnitude drawn uniformly from its benchmark range (``RANGES``, or
    ``gap_benchmark.ranges``) on one seed; an effect-free item has no effect; a leave-out item puts the effect at its
    range's middle with the effect left out of the library; the compound items are ``compound_items``'s.

    Parameters
    ----------
    cfg
        The ``gap_benchmark`` config block (keys left out: the schema's defaults); read: effects, ranges, magnitudes,
        seeds, effect_free, leave_out, compound.
    seed
        The config's seed, from which every magnitude is drawn.

    Returns
    -------
    items : dict
        {name: spec} with spec = {effect, magnitude (in the effect's own unit, ``rig.effects``), seed, library (None =
        all), kind}.

    Raises
    ------
    ValueError
        When ``gap_benchmark.effects`` names an unknown effect.
    """
    cfg = {**schema_defaults("gap_benchmark"), **dict(cfg or {})}
    effects = cfg.get("effects") or list(EFFECTS)
    unknown = [e for e in effects if e not in EFFECTS]
    if unknown:
        raise ValueError(f"gap_benchmark.effects: unknown {unknown}; known: {', '.join(EFFECTS)}")
    ranges = {**RANGES, **{k: tuple(v) for k, v in (cfg.get("ranges") or {}).items()}}
    n_mag = int(cfg["magnitudes"])
    seeds = [int(s) for s in cfg["seeds"]]
    items = {}
    for e in effects:
        lo, hi = ranges[e]
        for s in seeds:
            for k in range(n_mag):
                m = float(generator(seed, f"gap_benchmark/{e}/{k}/{s}").uniform(lo, hi))
                items[f"{e}-{k}-s{s}"] = {"effect": e, "magnitude": m, "seed": s, "library": None, "kind": "blind"}
    for s in seeds[: int(cfg["effect_free"])]:
        items[f"none-0-s{s}"] = {"effect": None, "magnitude": 0.0, "seed": s, "library": None, "kind": "effect_free"}
    if cfg["leave_out"]:
        for e in effects:
            lo, hi = ranges[e]
            lib = [x for x in EFFECTS if x != e]
            items[f"lo_{e}-0-s{seeds[0]}"] = {
                "effect": e,
                "magnitude": 0.5 * (lo + hi),
                "seed": seeds[0],
                "library": lib,
                "kind": "leave_out",
            }
    items.update(compound_items(int(cfg["compound"]), seeds, seed, ranges))
    return items


def expected_seconds(spec: Mapping) -> int:
    """Return a benchmark item's expected run time.

    The time is on one core of the 2-core reference machine, as the blind benchmark measured it, for the workflow's
    scheduler to start the long items first so that no core idles at the end waiting for one of them
    (``gap_benchmark_item``'s priority). The rig's truth sets it: a preload drift in a compound item (its later passes
    march whole records: 30-75 s) and a contact that opens (every simulation marched from the linear state: 31-38 s) are
    the long ones; most items take 10-20 s.

    Parameters
    ----------
    spec
        The item's spec (``benchmark_items``, ``ladder_items``); read: effect, magnitude, effects, kind, fraction.

    Returns
    -------
    seconds : int
        Expected run time [s].
    """
    effects = dict(spec.get("effects") or {})
    if spec.get("effect"):
        effects[spec["effect"]] = spec.get("magnitude", 0.0)
    if spec.get("kind") == "compound":
        return 35 if "preload_drift" in effects else 20
    if "contact_separation" in effects and spec.get("kind") != "leave_out":
        return 33 if spec.get("fraction", 1.0) > 0.5 else 12
    return 18 if spec.get("kind") == "leave_out" else 11


def ladder_typical(effect: str, ranges: Mapping = RANGES) -> float:
    """Return an effect's typical magnitude, kept inside its benchmark range's upper end.

    The typical magnitude is ``rig.effects``' typical value; contact separation's typical 7.2 makes lc3's impacts keep
    the motion from settling, so the range's upper end caps it.

    Parameters
    ----------
    effect
        The effect's name (a key of ``rig.effects.EFFECTS``).
    ranges
        {effect: (low, high)} benchmark ranges, each in its effect's own unit.

    Returns
    -------
    magnitude : float
        The typical magnitude in the effect's own unit (``EffectSpec.unit``), one of [-], [s], [s/m], [N s/m].
    """
    return float(min(EFFECTS[effect].typical, ranges[effect][1]))


def ladder_items(cfg: Mapping, seed: int) -> dict:
    """Return the detection ladder's items.

    The ladder (config gap_benchmark.ladder) puts each effect at fractions of its typical magnitude, for every seed:
    single-effect items named ``ladder_<effect>-<k>-s<seed>``.

    Parameters
    ----------
    cfg
        The ``gap_benchmark`` config block (keys left out: the schema's defaults); read: ladder, effects, ranges, seeds.
    seed
        The config's seed (the ladder's magnitudes are not drawn: unused).

    Returns
    -------
    items : dict
        {name: spec} with spec = {effect, magnitude, seed, library (None = all), kind "ladder", fraction}.
    """
    cfg = {**schema_defaults("gap_benchmark"), **dict(cfg or {})}
    fractions = [float(f) for f in cfg["ladder"]]
    effects = cfg.get("effects") or list(EFFECTS)
    ranges = {**RANGES, **{k: tuple(v) for k, v in (cfg.get("ranges") or {}).items()}}
    items = {}
    for e in effects:
        for s in [int(x) for x in cfg.get("seeds", [1, 2])]:
            for k, f in enumerate(fractions):
                items[f"ladder_{e}-{k}-s{s}"] = {
                    "effect": e,
                    "magnitude": f * ladder_typical(e, ranges),
                    "seed": s,
                    "library": None,
                    "kind": "ladder",
                    "fraction": f,
                }
    return items


def item_config(cfg: Mapping, spec: Mapping) -> tuple[dict, dict]:
    """Return the config of an item's rig and the effects it hides.

    A compound item's rig is perturbed as ``compound_config`` says.

    Parameters
    ----------
    cfg
        The base config, with the schema's defaults.
    spec
        The item's spec (``benchmark_items``, ``ladder_items``); read: effect, magnitude, kind, and a compound item's
        effects and perturbation.

    Returns
    -------
    config : dict
        The config of the item's rig.
    effects : dict
        {effect: magnitude (in the effect's own unit, ``rig.effects``)} the item hides.
    """
    effects = {spec["effect"]: spec["magnitude"]} if spec["effect"] else {}
    if spec["kind"] == "compound":
        cfg = compound_config(cfg, spec)
        effects = dict(spec["effects"])
    return cfg, effects


def hidden_text(spec: Mapping, effects: Mapping) -> str:
    """Return what an item hides, in words (for the log).

    Parameters
    ----------
    spec
        The item's spec; read: effect, magnitude, kind.
    effects
        {effect: magnitude} the item hides (``item_config``), for a compound item.

    Returns
    -------
    text : str
        "<effect> at <magnitude>", "no effect", or a compound item's perturbed rig with its effects.
    """
    hidden = f"{spec['effect']} at {spec['magnitude']:.4g}" if spec["effect"] else "no effect"
    if spec["kind"] == "compound":
        hidden = "perturbed rig with " + (", ".join(f"{e} at {m:.4g}" for e, m in effects.items()) or "no effect")
    return hidden


# ------------------------------------------------------------------------------------------
# compound items: a perturbed rig (its truth is not the model) with 0, 1 or 2 effects
# ------------------------------------------------------------------------------------------

# the effects a compound item may add (transducer masses are perturbed anyway; contact_separation is a load
# factor that may keep a perturbed rig from settling), by the place they act
COMPOUND_EFFECTS = {
    "tangential_contact": ("viscous_friction", "multi_asperity_friction"),
    "normal_contact": ("normal_contact_damping",),
    "structure_or_measurement": ("structural_damping", "channel_time_skew"),
    "non_stationary": ("preload_drift",),
}
PERTURBATION = {"youngs_modulus": 0.03, "transducer_masses": 0.4, "tangential_lever_arm": 0.08}
HARDENING_CUBIC = (2.0e19, 6.0e19)  # N/m^3 of the polynomial hardening N0 - k_n eta - k_3 eta^3
# N m/rad, log-uniform, of a clamp that gives (on half the compound rigs): the modes' frequencies lower and their shapes
# at the sensors changed much as relative channel gains change them (docs/gap.md, "Model updating")
CLAMP_STIFFNESS = (1.0e5, 1.0e6)
DAMPING_FORMS = ("modal", "stiffness_proportional", "mass_proportional")
# a compound rig's friction law away from Table 4's (log-uniform): mu and kappa themselves, e_f and k_c as factors on
# the configured truth's (the other simulator's other law: mu 0.33, kappa 0.25, e_f x 1.17, k_c x 0.82)
FRICTION_LAW_RANGES = {"mu": (0.28, 0.48), "kappa": (0.15, 0.42), "e_f_factor": (0.6, 1.7), "k_c_factor": (0.7, 1.4)}
# on a third of the compound rigs every damping ratio differs in the dual-sine tests from the random test's by this
# factor (uniform; rig.true_damping.dual_sine_factor): a damping that changes with level
DUAL_SINE_DAMPING = (0.85, 1.15)


def compound_items(n_per_seed: int, seeds: Sequence[int], seed: int, ranges: Mapping) -> dict:
    """Return the compound items: a perturbed rig with 0, 1 or 2 effects.

    Item k of each seed perturbs the rig's structure at random (E +-3 %, transducer masses +-40 %, lever arm +-8 %;
    polynomial hardening on or off; a damping form; on half of them a clamp that gives, CLAMP_STIFFNESS; on half a
    friction law away from Table 4's, FRICTION_LAW_RANGES; on a third Eq. 21 read with the slip limit; on a third the
    damping in the dual-sine tests other than in the random test, DUAL_SINE_DAMPING) and adds k mod 3 effects (two in
    different places), each at a random magnitude in its benchmark range.

    Parameters
    ----------
    n_per_seed
        Compound items per seed.
    seeds
        The rigs' seeds.
    seed
        The config's seed, from which every draw is made.
    ranges
        {effect: (low, high)} benchmark ranges, each in its effect's own unit.

    Returns
    -------
    items : dict
        {name: spec} with spec = {kind "compound", seed, effect None, magnitude 0, library None, effects, perturbation,
        normal_cubic_n_per_m3, damping_form, clamp_rotational_stiffness_nm_per_rad, friction_law,
        friction_regularization, dual_sine_damping_factor}.
    """
    items = {}
    places = list(COMPOUND_EFFECTS)
    for s in seeds:
        for k in range(int(n_per_seed)):
            rng = generator(seed, f"gap_benchmark/compound/{k}/{s}")
            pert = {name: float(rng.uniform(-a, a)) for name, a in PERTURBATION.items()}
            hardening = bool(rng.random() < 0.5)
            cubic = float(rng.uniform(*HARDENING_CUBIC)) if hardening else 0.0
            form = DAMPING_FORMS[int(rng.integers(len(DAMPING_FORMS)))]
            n_eff = k % 3
            chosen = rng.choice(len(places), size=n_eff, replace=False) if n_eff else []
            effects = {}
            for i in chosen:
                options = COMPOUND_EFFECTS[places[int(i)]]
                e = options[int(rng.integers(len(options)))]
                lo, hi = ranges[e]
                effects[e] = float(rng.uniform(lo, hi))
            # drawn last, so that the draws above (and the items before the clamp was added) stay as they were
            clamp = float(np.exp(rng.uniform(*np.log(CLAMP_STIFFNESS)))) if rng.random() < 0.5 else None
            # drawn after the clamp, for the same reason: on half the rigs a friction law away from Table 4's (the
            # identified law's form holds, its values do not), on a third Eq. 21 read with the slip limit
            law = (
                {k: float(np.exp(rng.uniform(*np.log(r)))) for k, r in FRICTION_LAW_RANGES.items()}
                if rng.random() < 0.5
                else None
            )
            regularization = "slip_limit" if rng.random() < 1.0 / 3.0 else "none"
            # drawn last, for the same reason
            dual_sine = float(rng.uniform(*DUAL_SINE_DAMPING)) if rng.random() < 1.0 / 3.0 else 1.0
            items[f"compound-{k}-s{s}"] = {
                "kind": "compound",
                "seed": int(s),
                "effect": None,
                "magnitude": 0.0,
                "library": None,
                "effects": effects,
                "perturbation": pert,
                "normal_cubic_n_per_m3": cubic,
                "damping_form": form,
                "clamp_rotational_stiffness_nm_per_rad": clamp,
                "friction_law": law,
                "friction_regularization": regularization,
                "dual_sine_damping_factor": dual_sine,
            }
    return items


def compound_config(cfg: Mapping, spec: Mapping) -> dict:
    """Return the config of a compound item's rig.

    rig.true_structure (with its clamp), the normal law, the damping form, the friction law's values and its reading of
    Eq. 21 are perturbed as ``spec`` says; the identification keeps ``structure`` and ``friction``.

    Parameters
    ----------
    cfg
        The base config, with the schema's defaults; read: structure (beam.youngs_modulus_pa, sensors.masses_kg,
        force_transducer_mass_kg, contact_geometry.tangential_lever_arm_m) and rig.truth (normal, friction).
    spec
        The compound item's spec (``compound_items``).

    Returns
    -------
    config : dict
        A deep copy of ``cfg`` with rig.true_structure, rig.truth.normal, rig.true_damping and rig.truth.friction set.
    """
    import copy

    out = copy.deepcopy(dict(cfg))
    st, p = out["structure"], spec["perturbation"]
    rig = out["rig"]
    rig["true_structure"] = {
        "beam": {"youngs_modulus_pa": st["beam"]["youngs_modulus_pa"] * (1 + p["youngs_modulus"])},
        "sensors": {"masses_kg": [m * (1 + p["transducer_masses"]) for m in st["sensors"]["masses_kg"]]},
        "force_transducer_mass_kg": st["force_transducer_mass_kg"] * (1 + p["transducer_masses"]),
        "contact_geometry": {
            "tangential_lever_arm_m": st["contact_geometry"]["tangential_lever_arm_m"] * (1 + p["tangential_lever_arm"])
        },
    }
    if spec.get("clamp_rotational_stiffness_nm_per_rad"):
        rig["true_structure"]["clamp_rotational_stiffness_nm_per_rad"] = float(
            spec["clamp_rotational_stiffness_nm_per_rad"]
        )
    if spec["normal_cubic_n_per_m3"]:
        rig["truth"]["normal"] = {
            **rig["truth"]["normal"],
            "exponent": 1.0,
            "cubic_n_per_m3": float(spec["normal_cubic_n_per_m3"]),
        }
    rig["true_damping"] = {
        "form": spec["damping_form"],
        "reference_frequency_hz": 54.4,
        "dual_sine_factor": float(spec.get("dual_sine_damping_factor", 1.0)),
    }
    law, fr = spec.get("friction_law"), dict(rig["truth"]["friction"])
    if law:
        fr.update(
            mu=law["mu"],
            kappa=law["kappa"],
            e_f_n_per_m=fr["e_f_n_per_m"] * law["e_f_factor"],
            k_c_per_m=fr["k_c_per_m"] * law["k_c_factor"],
        )
    if spec.get("friction_regularization"):
        fr["regularization"] = spec["friction_regularization"]
    rig["truth"]["friction"] = fr
    return out
