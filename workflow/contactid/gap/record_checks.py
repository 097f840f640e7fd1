"""Plausibility of the records against each other and against the identified model: a units factor, a flipped sign,
a swapped channel, a gross disagreement.

Each record passed its own checks (``raw_checks``); these look at what no single record shows. Evidence first (pure
numbers from the records and the identified model's predictions at each record's measured force), then the
decisions, each a small pure function of the evidence and a threshold, applied in a fixed order, every one recorded
in the trace:

* ``level_tests`` (before identification, the records alone): each load case's accelerance at its drive (every
  sensor's harmonic over the force's, at w and 3 w) against the other cases'. Cases of one rig driven at one
  frequency differ by their level's nonlinearity, a few tens of per cent; a case a units factor away from the
  others (9.81 for g, 1000 for mm/s^2 or kN) was written in other units than its label says.
* ``model_tests`` (after identification): each case's record against the identified model's prediction at the
  record's measured force. The calibration case fits by construction; a held-out case of the same rig leaves a gap
  of the same order. A record that is a sign-flipped, units-scaled or channel-permuted copy of its prediction (the
  transformation leaves a small part of the gap) is a sign, units or channel-map error, named with its factor. A
  units factor counts only where the record's level among its peers shows it too: a contact that opens at one
  level makes the model overpredict that record several times, and the record's level among its peers is then as
  theirs (the blind benchmark's contact-separation items).

A finding is a message naming the record, the likely cause and the fix. It goes to the console, ``summary.json``'s
``data_warnings``, the report's first page, and the gap diagnosis, whose verdict becomes ``records_disagree``: no
unmodelled effect is to be looked for in records that disagree with each other in this way.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..units_factors import near_units, units_error


@dataclass(frozen=True)
class Thresholds:
    """The tests' limits (config ``gap.record_checks``).

    level_factor: a case's accelerance this many times off the cases' median (or its inverse) is named;
    explained_share: a transformation (scale, sign, channel order) explains a disagreement when it leaves at most
    this share of the gap; gross_ratio, signature_gap: a held-out case leaving more than gross_ratio times the
    calibration case's gap and more than signature_gap is looked at for a transformation; gross_gap: beyond it (and
    gross_ratio times the calibration case's) with none, a gross disagreement of unknown cause; unit_tolerance: a factor
    within this relative distance of a units factor is named as that factor."""

    level_factor: float = 3.0
    explained_share: float = 0.35
    gross_ratio: float = 10.0
    signature_gap: float = 0.05
    gross_gap: float = 0.3
    unit_tolerance: float = 0.15

    @classmethod
    def from_config(cls, block: Mapping | None) -> "Thresholds":
        """From the ``gap.record_checks`` block (keys left out: the defaults), as ``verdict.PlaceThresholds``."""
        return cls(**{k: float(v) for k, v in (block or {}).items()})


# -------------------------------------------------------------------------------------------------------------------
# evidence
# -------------------------------------------------------------------------------------------------------------------


def accelerance_levels(checks: Mapping[str, Mapping]) -> dict:
    """{case: (f0 in Hz, (j, 2) complex accelerance at w and 3 w)} of every sensor from the records' harmonics
    ``checks`` {case: {"f0": Hz, "acceleration": (j, H) complex, "force": (H,) complex}}."""
    out = {}
    for case, c in checks.items():
        A, F = np.asarray(c["acceleration"]), np.asarray(c["force"])
        hs = [h for h in (0, 2) if h < F.size and abs(F[h]) > 0]
        out[case] = (float(c["f0"]), np.stack([A[:, h] / F[h] for h in hs], axis=1))
    return out


# load cases driven within this relative distance of each other's frequency are compared by their accelerance
SAME_DRIVE = 0.005


def same_drive_groups(levels: Mapping[str, tuple]) -> list[list[str]]:
    """The cases of ``levels`` (``accelerance_levels``) grouped by drive frequency (within ``SAME_DRIVE``): the
    accelerance of one structure depends on the frequency, so only cases driven alike are compared."""
    groups: list[list[str]] = []
    for case in sorted(levels, key=lambda c: levels[c][0]):
        if groups and abs(levels[case][0] / levels[groups[-1][0]][0] - 1.0) <= SAME_DRIVE:
            groups[-1].append(case)
        else:
            groups.append([case])
    return groups


def _ls_scale(pred: np.ndarray, meas: np.ndarray) -> complex:
    """The complex factor a minimising |a pred - meas|."""
    den = np.vdot(pred, pred)
    return complex(np.vdot(pred, meas) / den) if abs(den) > 0 else 0j


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300))


@dataclass(frozen=True)
class ModelEvidence:
    """One record against the identified model's prediction at its measured force (harmonics 1..H of every sensor):
    the gap; the common complex factor of prediction onto record and the gap it leaves; each sensor's factor and gap;
    the channel permutation that fits best (sensor order) and the gap it leaves."""

    case: str
    sensors: tuple
    gap: float
    scale: complex
    gap_scaled: float
    sensor_scale: tuple
    sensor_gap: tuple
    permutation: tuple
    gap_permuted: float


def model_evidence(case: str, sensors, measured: np.ndarray, predicted: np.ndarray) -> ModelEvidence:
    """``measured`` and ``predicted``: (j, H) complex accelerations of one record and of the model at its force."""
    A, P = np.asarray(measured), np.asarray(predicted)
    a = _ls_scale(P.ravel(), A.ravel())
    per = [_ls_scale(P[i], A[i]) for i in range(A.shape[0])]
    gaps = [_rel(P[i], A[i]) for i in range(A.shape[0])]
    gap = _rel(P, A)
    best, best_gap = tuple(range(A.shape[0])), gap
    if A.shape[0] <= 6:  # at most 720 orders; beyond that the channel-map test is left out
        for perm in itertools.permutations(range(A.shape[0])):
            g = _rel(P[list(perm)], A)
            if g < best_gap - 1e-12:
                best, best_gap = perm, g
    return ModelEvidence(
        case,
        tuple(sensors),
        gap,
        a,
        _rel(a * P, A),
        tuple(per),
        tuple(gaps),
        best,
        best_gap,
    )


# -------------------------------------------------------------------------------------------------------------------
# decisions
# -------------------------------------------------------------------------------------------------------------------


def named_factor(factor: float, tol: float) -> str:
    """A magnitude ratio (record over expectation) and what it most likely means: the units factor it is near, either
    way (``units_factors``), or a sensitivity."""
    hit = units_error(factor, tol)
    if hit is not None:
        value, meaning = hit
        near = f"1/{1 / value:g}" if value < 1 else f"{value:g}"
        return f"{factor:.3g} times (near {near}: likely {meaning})"
    return f"{factor:.3g} times (likely a wrong sensitivity or gain in the channel map)"


def _trace(test: str, value: float, threshold: float, passed: bool, case: str) -> dict:
    return {"test": test, "case": case, "value": float(value), "threshold": float(threshold), "passed": bool(passed)}


def _finding(case: str, check: str, message: str, signature: bool) -> dict:
    """``signature``: the cause is a transformation of the record (units, sign, channel order), not a guess."""
    return {"record": case, "check": check, "message": message, "signature": signature}


def level_factors(levels: Mapping[str, tuple]) -> dict:
    """{case: its accelerance over the median of its drive group's (``same_drive_groups``; the geometric median over
    sensors and harmonics)} for every case that shares its drive with another; with two, each over the other."""
    out = {}
    for cases in same_drive_groups(levels):
        if len(cases) < 2:
            continue
        for case in cases:
            others = [c for c in cases if c != case]
            # the median of every case (its own included: one case off cannot move it) or, with two, the other case
            ref = np.median(np.abs(np.stack([levels[c][1] for c in (cases if len(cases) > 2 else others)])), axis=0)
            out[case] = float(np.exp(np.median(np.log(np.abs(levels[case][1]) / ref))))
    return out


def level_tests(levels: Mapping[str, tuple], th: Thresholds) -> tuple[list, list]:
    """Each case's accelerance (``accelerance_levels``) against the median of every case's driven at its frequency
    (``level_factors``): (findings, trace). Needs three cases at a drive to say which one is off; with two, a ratio
    beyond the limit names both. A units factor is named within twice ``unit_tolerance`` here: the cases' own
    accelerances differ by their levels' nonlinearity."""
    findings, trace = [], []
    factors = level_factors(levels)
    for cases in same_drive_groups(levels):
        for case in (c for c in cases if c in factors):
            factor = factors[case]
            others = [c for c in cases if c != case]
            off = max(factor, 1.0 / factor)
            passed = off <= th.level_factor
            trace.append(_trace("accelerance_level_against_other_cases", off, th.level_factor, passed, case))
            if passed:
                continue
            who = case if len(cases) > 2 else f"{case} or {others[0]}"
            findings.append(
                _finding(
                    case,
                    "accelerance_level",
                    f"{who}: its accelerations over its force at the drive are "
                    f"{named_factor(factor, 2 * th.unit_tolerance)} those of the other load cases "
                    f"({', '.join(others)}); check the record's units and sensitivities (force and accelerations) "
                    "against its channel map",
                    True,
                )
            )
    return findings, trace


def model_tests(
    evidence: Mapping[str, ModelEvidence], calibration_case: str, th: Thresholds, levels: Mapping | None = None
) -> tuple[list, list]:
    """Each record against the model's prediction at its force. A held-out record is looked at where its gap exceeds
    ``gross_ratio`` times the calibration case's and ``signature_gap``; any record, the calibration case's included,
    where it exceeds ``gross_gap`` (a model that leaves that much on the record it was fitted to has failed on it,
    and the held-out records are then no worse than it).
    Looked at, in this order: a common factor that explains the disagreement (leaves at most ``explained_share`` of
    it) and is a flipped sign, or a units factor that the record's level among its peers (``levels``, from
    ``level_factors``) shows too (a factor of any other size, or one the peers do not show, is the model's: an effect
    it lacks at that level); a channel order that explains it (the channel
    map); one sensor off by its own factor while the others agree (its sensitivity or sign). With none of these, a
    gap beyond ``gross_gap`` (and, held out, ``gross_ratio`` times the calibration case's) is a gross disagreement of
    unknown cause (no signature: the verdict is not taken from it). Returns (findings, trace)."""
    findings, trace = [], []
    cal = evidence.get(calibration_case)
    base = cal.gap if cal is not None else 0.0
    for case, ev in evidence.items():
        own = case == calibration_case
        limit = th.gross_gap if own else min(th.gross_gap, max(th.gross_ratio * base, th.signature_gap))
        disagrees = ev.gap > limit
        trace.append(
            _trace("gap_of_calibration" if own else "gap_against_calibration", ev.gap, limit, not disagrees, case)
        )
        if not disagrees:
            continue
        if own:
            head = (
                f"{case}: the identified model does not reproduce even its calibration record ({ev.gap:.1%} at its "
                "measured force)"
            )
        else:
            head = (
                f"{case}: the record disagrees with the identified model's prediction at its measured force "
                f"({ev.gap:.1%} against {base:.2%} on the calibration case {calibration_case})"
            )
        finding = _signature(ev, th, head, trace, (levels or {}).get(case))
        if finding is None and ev.gap > (th.gross_gap if own else max(th.gross_ratio * base, th.gross_gap)):
            finding = _finding(
                case,
                "gross",
                f"{head}: the records disagree with the model grossly, and no units factor, sign or channel order "
                "explains it: an effect the identified model lacks at this level (the gap diagnosis looks for it), or "
                "a structure that changed between tests; if neither, check units, signs and the channel map",
                False,
            )
        if finding is not None:
            findings.append(finding)
    return findings, trace


def _signature(ev: ModelEvidence, th: Thresholds, head: str, trace: list, level: float | None) -> dict | None:
    """The first transformation of the record that explains its disagreement with the prediction, as a finding;
    ``level``: the record's accelerance over its peers' (``level_factors``), None where it has none."""
    case, n = ev.case, len(ev.sensors)
    mag, phase = abs(ev.scale), float(np.degrees(abs(np.angle(ev.scale))))
    left = ev.gap_scaled / ev.gap
    big = max(mag, 1.0 / max(mag, 1e-300))
    # a units factor is the record's, not the model's, where the record's accelerance against the other cases'
    # (``level``, where other cases share its drive) is off beyond level_factor by about the same factor: an effect
    # the model lacks (a contact that opens at one level) moves the prediction, not the record's level among its
    # peers (the blind benchmark's contact-separation items: the prediction 4-5 times the record, near 1/4.448)
    if level is None:  # no peer to ask: the factor alone, within a third of the tolerance
        units = near_units(mag, th.unit_tolerance / 3.0)
    else:  # the peers see the record off beyond level_factor, by about the same factor
        units = (
            near_units(mag, th.unit_tolerance)
            and max(level, 1.0 / level) > th.level_factor
            and abs(np.log(level / max(mag, 1e-300))) < np.log(1.0 + 2.0 * th.unit_tolerance)
        )
    explained = left <= th.explained_share and (phase > 135.0 or units)
    trace.append(_trace("common_factor_explains", left, th.explained_share, not explained, case))
    if explained:
        parts = []
        if units and big >= 1.5:
            parts.append(f"its accelerations are {named_factor(mag, th.unit_tolerance)} the prediction")
        if phase > 135.0:
            parts.append("of opposite sign (the force's or every accelerometer's sign is flipped)")
        return _finding(
            case, "units_or_sign", f"{head}: {' and '.join(parts)}; correct the record or its channel map", True
        )
    left = ev.gap_permuted / ev.gap
    reordered = ev.permutation != tuple(range(n)) and left <= th.explained_share
    trace.append(_trace("channel_order_explains", left, th.explained_share, not reordered, case))
    if reordered:
        moved = [
            f"{ev.sensors[i]} holds what is predicted at {ev.sensors[p]}"
            for i, p in enumerate(ev.permutation)
            if i != p
        ]
        return _finding(
            case,
            "channel_map",
            f"{head}: with its channels reordered it leaves {ev.gap_permuted:.1%} ({'; '.join(moved)}): the channel "
            "map is likely swapped; correct the sensor order or positions",
            True,
        )
    gaps = np.asarray(ev.sensor_gap)
    if n < 2:
        return None
    worst = int(np.argmax(gaps))
    a = ev.sensor_scale[worst]
    rest = float(np.max(np.delete(gaps, worst)))
    off = max(abs(a), 1.0 / max(abs(a), 1e-300))
    alone = rest <= 0.5 * gaps[worst] and (off >= 1.3 or abs(np.angle(a)) > np.radians(135.0))
    trace.append(_trace("one_channel_explains", rest / gaps[worst], 0.5, not alone, case))
    if not alone:
        return None
    if abs(np.angle(a)) > np.radians(135.0):
        what = "with the opposite sign" + (f", {named_factor(abs(a), th.unit_tolerance)}" if off >= 1.3 else "")
    else:
        what = named_factor(abs(a), th.unit_tolerance)
    return _finding(
        case,
        "one_channel",
        f"{head}: channel {ev.sensors[worst]} reads {what} its prediction while the others agree; correct that "
        "channel's sensitivity or sign",
        True,
    )


def records_check(
    levels: Mapping[str, np.ndarray], evidence: Mapping[str, ModelEvidence], calibration_case: str, th: Thresholds
) -> dict:
    """The whole check: {"passed", "findings": [{record, check, message, signature}], "trace": [...], "gaps": {case:
    gap}}; ``passed`` is False where a finding has a signature (a units factor, a sign, a channel order: the records,
    not the model, are wrong)."""
    f1, t1 = level_tests(levels, th)
    f2, t2 = model_tests(evidence, calibration_case, th, level_factors(levels))
    return {
        "passed": not any(f["signature"] for f in f1 + f2),
        "findings": f1 + f2,
        "trace": t1 + t2,
        "gaps": {c: e.gap for c, e in evidence.items()},
        "calibration_case": calibration_case,
    }


# the gap diagnosis's verdict where a record fails with a signature (contract: an effect name, "none", or this)
RECORDS_DISAGREE = "records_disagree"


def diagnosis_outcome(verdict: str, reason: str, explanation: list, check: Mapping) -> tuple[str, str, list]:
    """The gap diagnosis's (verdict, reason, explanation) given the records' check: where a record fails with a
    signature (units, sign, channel order), verdict ``records_disagree``, the reason naming each such record and its
    fix, and no explanation (no effect is to be looked for in records that contradict each other); a gross
    disagreement of unknown cause is said first in the reason, the verdict kept; otherwise unchanged."""
    hard = [f for f in check.get("findings", []) if f.get("signature")]
    soft = [f for f in check.get("findings", []) if not f.get("signature")]
    if hard:
        worst = max((check.get("gaps") or {}).get(f["record"], 0.0) for f in hard)
        said = "; ".join(f["message"] for f in hard)
        return (
            RECORDS_DISAGREE,
            f"the records disagree with the model grossly ({worst:.0%} held out): check units, signs, channel map. "
            + said,
            [],
        )
    if soft:
        return verdict, "; ".join(f["message"] for f in soft) + ". Diagnosis: " + reason, explanation
    return verdict, reason, explanation
