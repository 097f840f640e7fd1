"""Plausibility of the records against each other and against the identified model.

What is looked for: a units factor, a flipped sign, a swapped channel, a gross disagreement.

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
from typing import Mapping, Sequence

import numpy as np

from ..units_factors import near_units, units_error


@dataclass(frozen=True)
class Thresholds:
    """The tests' limits (config ``gap.record_checks``).

    Attributes
    ----------
    level_factor
        A case's accelerance this many times off the cases' median (or its inverse) is named [-].
    explained_share
        A transformation (scale, sign, channel order) explains a disagreement when it leaves at most this share of
        the gap [-].
    gross_ratio
        A held-out case leaving more than gross_ratio times the calibration case's gap (and more than
        signature_gap) is looked at for a transformation [-].
    signature_gap
        The held-out gap (relative) below which no record is looked at for a transformation [-].
    gross_gap
        Beyond this gap (relative; and, held out, gross_ratio times the calibration case's) with no transformation,
        a gross disagreement of unknown cause [-].
    unit_tolerance
        A factor within this relative distance of a units factor is named as that factor [-].
    """

    level_factor: float = 3.0
    explained_share: float = 0.35
    gross_ratio: float = 10.0
    signature_gap: float = 0.05
    gross_gap: float = 0.3
    unit_tolerance: float = 0.15

    @classmethod
    def from_config(cls, block: Mapping | None) -> "Thresholds":
        """Return the thresholds of the ``gap.record_checks`` block, as ``place.PlaceThresholds`` does.

        Parameters
        ----------
        block
            The config's ``gap.record_checks`` block (keys left out: the defaults); None for every default.

        Returns
        -------
        thresholds : Thresholds
            The block's values as floats.
        """
        return cls(**{k: float(v) for k, v in (block or {}).items()})


# -------------------------------------------------------------------------------------------------------------------
# evidence
# -------------------------------------------------------------------------------------------------------------------


def accelerance_levels(checks: Mapping[str, Mapping]) -> dict:
    """Return every case's drive frequency and the accelerance of every sensor at w and 3 w.

    Computed from the records' harmonics: each sensor's harmonic over the force's.

    Parameters
    ----------
    checks
        {case: {"f0": drive frequency [Hz], "acceleration": the sensors' complex harmonics h = 1..H [m/s^2] of
        shape (j, H), "force": the force's complex harmonics [N] of shape (H,)}}.

    Returns
    -------
    levels : dict
        {case: (f0 [Hz], complex accelerance [m/s^2/N] of shape (j, 2): at w and 3 w)}; a harmonic the force
        lacks (beyond H, or zero) is left out, leaving fewer columns.
    """
    out = {}
    for case, c in checks.items():
        A, F = np.asarray(c["acceleration"]), np.asarray(c["force"])
        hs = [h for h in (0, 2) if h < F.size and abs(F[h]) > 0]
        out[case] = (float(c["f0"]), np.stack([A[:, h] / F[h] for h in hs], axis=1))
    return out


# load cases driven within this relative distance of each other's frequency are compared by their accelerance
SAME_DRIVE = 0.005


def same_drive_groups(levels: Mapping[str, tuple]) -> list[list[str]]:
    """Return the cases grouped by drive frequency (within ``SAME_DRIVE``, relative).

    The accelerance of one structure depends on the frequency, so only cases driven alike are compared.

    Parameters
    ----------
    levels
        {case: (f0 [Hz], accelerance)} (``accelerance_levels``).

    Returns
    -------
    groups : list[list[str]]
        The cases by ascending drive frequency, each group within ``SAME_DRIVE`` of its first case's frequency.
    """
    groups: list[list[str]] = []
    for case in sorted(levels, key=lambda c: levels[c][0]):
        if groups and abs(levels[case][0] / levels[groups[-1][0]][0] - 1.0) <= SAME_DRIVE:
            groups[-1].append(case)
        else:
            groups.append([case])
    return groups


def _ls_scale(pred: np.ndarray, meas: np.ndarray) -> complex:
    """Return the complex factor a minimising |a pred - meas|."""
    den = np.vdot(pred, pred)
    return complex(np.vdot(pred, meas) / den) if abs(den) > 0 else 0j


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300))


@dataclass(frozen=True)
class ModelEvidence:
    """One record against the identified model's prediction at its measured force (harmonics 1..H of every sensor).

    The gap; the common complex factor of prediction onto record and the gap it leaves; each sensor's factor and gap;
    the channel permutation that fits best (sensor order) and the gap it leaves. A gap is the norm of prediction
    minus record relative to the record's norm.

    Attributes
    ----------
    case
        The load case.
    sensors
        The sensors' names, j of them, in the order of the harmonics' rows.
    gap
        The prediction's gap to the record [-].
    scale
        The common complex factor a (least squares) that takes the prediction onto the record [-].
    gap_scaled
        The gap of a times the prediction [-].
    sensor_scale
        Each sensor's own complex factor of prediction onto record [-], j of them.
    sensor_gap
        Each sensor's gap [-], j of them.
    permutation
        The order of the predicted rows that fits the record best (the identity where none fits better, or where
        more than six sensors leave the test out).
    gap_permuted
        The gap of the prediction in that order [-].
    """

    case: str
    sensors: tuple
    gap: float
    scale: complex
    gap_scaled: float
    sensor_scale: tuple
    sensor_gap: tuple
    permutation: tuple
    gap_permuted: float


def model_evidence(case: str, sensors: Sequence[str], measured: np.ndarray, predicted: np.ndarray) -> ModelEvidence:
    """Return the evidence of one record against the model's prediction at its force.

    Parameters
    ----------
    case
        The load case.
    sensors
        The sensors' names, j of them, in the order of the rows.
    measured
        The record's complex acceleration harmonics h = 1..H [m/s^2], shape (j, H).
    predicted
        The identified model's at the record's measured force [m/s^2], shape (j, H).

    Returns
    -------
    evidence : ModelEvidence
        The gaps, the common and per-sensor factors and the best channel order.
    """
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
    """Return a magnitude ratio (record over expectation) in words, with what it most likely means.

    The units factor it is near, either way (``units_factors``), or a sensitivity.

    Parameters
    ----------
    factor
        The magnitude ratio, record over expectation [-].
    tol
        Relative distance from a units factor within which the ratio is named as that factor [-].

    Returns
    -------
    text : str
        "x times (near f: likely ...)" or "x times (likely a wrong sensitivity or gain in the channel map)".
    """
    hit = units_error(factor, tol)
    if hit is not None:
        value, meaning = hit
        near = f"1/{1 / value:g}" if value < 1 else f"{value:g}"
        return f"{factor:.3g} times (near {near}: likely {meaning})"
    return f"{factor:.3g} times (likely a wrong sensitivity or gain in the channel map)"


def _trace(test: str, value: float, threshold: float, passed: bool, case: str) -> dict:
    return {"test": test, "case": case, "value": float(value), "threshold": float(threshold), "passed": bool(passed)}


def _finding(case: str, check: str, message: str, signature: bool) -> dict:
    """Return a finding; ``signature``: the cause is a transformation of the record (units, sign, channel order)."""
    return {"record": case, "check": check, "message": message, "signature": signature}


def level_factors(levels: Mapping[str, tuple]) -> dict:
    """Return each case's accelerance over the median of its drive group's (``same_drive_groups``).

    The geometric median over sensors and harmonics of the case's accelerance over the group's median, for every
    case that shares its drive with another; with two, each over the other.

    Parameters
    ----------
    levels
        {case: (f0 [Hz], accelerance)} (``accelerance_levels``).

    Returns
    -------
    factors : dict
        {case: its accelerance over its peers' [-]}; a case alone at its drive is left out.
    """
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
    """Test each case's accelerance against the median of every case's driven at its frequency (``level_factors``).

    Needs three cases at a drive to say which one is off; with two, a ratio beyond the limit names both. A units
    factor is named within twice ``unit_tolerance`` here: the cases' own accelerances differ by their levels'
    nonlinearity.

    Parameters
    ----------
    levels
        {case: (f0 [Hz], accelerance)} (``accelerance_levels``).
    th
        The tests' limits.

    Returns
    -------
    findings : list
        A finding (record, check, message, signature) per case off beyond ``level_factor``.
    trace : list
        Each test made: test, case, value, threshold, passed.
    """
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
    """Test each record against the model's prediction at its force.

    A held-out record is looked at where its gap exceeds ``gross_ratio`` times the calibration case's and
    ``signature_gap``; any record, the calibration case's included, where it exceeds ``gross_gap`` (a model that
    leaves that much on the record it was fitted to has failed on it, and the held-out records are then no worse
    than it). Looked at, in this order: a common factor that explains the disagreement (leaves at most
    ``explained_share`` of it) and is a flipped sign, or a units factor that the record's level among its peers
    (``levels``, from ``level_factors``) shows too (a factor of any other size, or one the peers do not show, is the
    model's: an effect it lacks at that level); a channel order that explains it (the channel map); one sensor off by
    its own factor while the others agree (its sensitivity or sign). With none of these, a gap beyond ``gross_gap``
    (and, held out, ``gross_ratio`` times the calibration case's) is a gross disagreement of unknown cause (no
    signature: the verdict is not taken from it).

    Parameters
    ----------
    evidence
        {case: ModelEvidence} of every record.
    calibration_case
        The case the friction law was fitted on.
    th
        The tests' limits.
    levels
        {case: the record's accelerance over its peers' [-]} (``level_factors``); None, or a case left out: no peer
        to ask.

    Returns
    -------
    findings : list
        A finding (record, check, message, signature) per record that disagrees with a signature or grossly.
    trace : list
        Each test made: test, case, value, threshold, passed.
    """
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
    """Return the first transformation of the record that explains its disagreement with the prediction, as a finding.

    ``level``: the record's accelerance over its peers' (``level_factors``), None where it has none.
    """
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
    levels: Mapping[str, tuple], evidence: Mapping[str, ModelEvidence], calibration_case: str, th: Thresholds
) -> dict:
    """Run the whole check: the records' levels against each other, then each record against the model.

    ``passed`` is False where a finding has a signature (a units factor, a sign, a channel order: the records, not
    the model, are wrong).

    Parameters
    ----------
    levels
        {case: (f0 [Hz], accelerance)} (``accelerance_levels``).
    evidence
        {case: ModelEvidence} of every record.
    calibration_case
        The case the friction law was fitted on.
    th
        The tests' limits.

    Returns
    -------
    check : dict
        {"passed", "findings": [{record, check, message, signature}], "trace": [...], "gaps": {case: gap},
        "calibration_case"}.
    """
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
    """Return the gap diagnosis's (verdict, reason, explanation) given the records' check.

    Where a record fails with a signature (units, sign, channel order), verdict ``records_disagree``, the reason
    naming each such record and its fix, and no explanation (no effect is to be looked for in records that contradict
    each other); a gross disagreement of unknown cause is said first in the reason, the verdict kept; otherwise
    unchanged.

    Parameters
    ----------
    verdict
        The diagnosis's verdict (an effect's name or "none").
    reason
        The diagnosis's reason, in words.
    explanation
        The diagnosis's explanation, its steps.
    check
        The records' check (``records_check``).

    Returns
    -------
    verdict : str
        ``RECORDS_DISAGREE`` or the verdict given.
    reason : str
        The reason, with the findings said.
    explanation : list
        The explanation given, or empty where the records disagree.
    """
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
