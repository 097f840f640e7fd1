"""The decisions the story is told from: each a small pure function returning its trace entry, and the resolution.

Each decision (a ``Test``) holds one number of the diagnosis against one threshold of the gap settings and says in
words what it found: ``held_out``, ``update_counts``, ``above_floor``, ``beyond_scatter``, ``shrinks_gap``,
``beyond_model_form`` and ``acts_where_gap_lies`` in the order ``story.tell`` applies them; ``records_agree``, the
records' check as a decision; ``first_pass_best``, the first pass's best candidate where the explanation added no
effect. ``resolution`` turns the same thresholds into what the records can attribute: the smallest change of the
held-out gap a first effect must make.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

from .place import acts_where
from .verdict import percent, setting

if TYPE_CHECKING:
    from .settings import GapSettings


@dataclass(frozen=True)
class Test:
    """One decision of the story, an entry of its trace.

    Attributes
    ----------
    test
        Which test ("held_out", "update_counts", "above_floor", ...).
    value
        The test's value [-]: a held-out gap or its change (fractions), a count, or words (the alternatives, a
        place).
    threshold
        What the value is held against [-], in the value's terms.
    passed
        Whether the test passed.
    says
        What it says in words (the reason sentence where it decides).
    step
        The step (effect) it was applied to; "" for the whole diagnosis.
    """

    test: str
    value: float | str | bool | None
    threshold: float | str | None
    passed: bool
    says: str
    step: str = ""

    def as_dict(self) -> dict:
        """Return the decision as a trace entry of diagnosis.json.

        Returns
        -------
        entry : dict
            {test, step, value, threshold, passed, says}.
        """
        return {
            "test": self.test,
            "step": self.step,
            "value": self.value,
            "threshold": self.threshold,
            "passed": bool(self.passed),
            "says": self.says,
        }


def held_out(n_held: int) -> Test:
    """Test whether at least one load case is held out, without which no effect can be tested.

    Parameters
    ----------
    n_held
        How many load cases are held out.

    Returns
    -------
    test : Test
        The decision "held_out" (value ``n_held``, threshold 1).
    """
    ok = n_held >= 1
    return Test(
        "held_out",
        n_held,
        1,
        ok,
        f"{n_held} load case(s) held out"
        if ok
        else "no load case is held out (one is configured): every gap here is the calibration case's own, which "
        "refitting any candidate lowers, so no effect can be tested; add a second load case (config load_cases) to "
        "predict",
    )


def update_counts(gap_before: float, gap_after: float, scatter: float, noise_factor: float) -> Test:
    """Test whether an accepted model update is a step of the explanation.

    It is one where it shrinks the held-out gap by more than noise_factor x the records' scatter.

    Parameters
    ----------
    gap_before
        Held-out gap before the update (a fraction) [-].
    gap_after
        Held-out gap after the update [-].
    scatter
        The records' bootstrap scatter of the held-out gap [-].
    noise_factor
        Factor on the scatter the drop must exceed (gap.noise_factor) [-].

    Returns
    -------
    test : Test
        The decision "update_counts" of the step "model_updating" (value the drop, threshold noise_factor x scatter).
    """
    drop = gap_before - gap_after
    ok = bool(np.isfinite(drop) and drop > noise_factor * scatter)
    return Test(
        "update_counts",
        float(drop),
        float(noise_factor * scatter),
        ok,
        f"model updating takes the held-out gap from {percent(gap_before)} to {percent(gap_after)}"
        + (
            ""
            if ok
            else ": no more than the records' scatter, so it explains none of the gap (the diagnosis starts "
            "from the updated model, where.model_updating)"
        ),
        "model_updating",
    )


def records_agree(check: Mapping) -> Test:
    """Test the records' check (rule record_checks): no record fails with a signature (units, sign, channel order).

    Where one does, the verdict is records_disagree and nothing is explained (``record_checks.diagnosis_outcome``).

    Parameters
    ----------
    check
        The records' check: its ``findings``, each a mapping with ``signature`` (set where a record is wrong by a
        units factor, a sign or a channel order) and ``message``.

    Returns
    -------
    test : Test
        The decision "records_agree" (value the count of such findings, threshold 0).
    """
    hard = [f for f in check.get("findings", []) if f.get("signature")]
    return Test(
        "records_agree",
        len(hard),
        0,
        not hard,
        "the records' check finds no record wrong by a units factor, a sign or a channel order"
        if not hard
        else "; ".join(f["message"] for f in hard),
    )


def acts_where_gap_lies(effect: str, acts_on: str, place: str, ok: bool | None = None) -> Test:
    """Test whether the explanation's effects act where the localisation puts the gap.

    Parameters
    ----------
    effect
        The explanation's effects, "a or b".
    acts_on
        Where they act ("a | b").
    place
        Where the localisation puts the gap.
    ok
        Whether one of them acts there, when several; None: ``place.acts_where(acts_on, place)``.

    Returns
    -------
    test : Test
        The decision "acts_where_gap_lies" of the step ``effect``.
    """
    ok = acts_where(acts_on, place) if ok is None else bool(ok)
    return Test(
        "acts_where_gap_lies",
        acts_on,
        place,
        ok,
        f"{effect} acts on {acts_on}"
        + ("" if ok else f", and the gap lies in {place}: no candidate of the library that acts there explains it"),
        effect,
    )


def above_floor(gap: float, min_gap: float, effect: str = "") -> Test:
    """Test whether the held-out gap is at or above the identification's floor gap.min_gap.

    Parameters
    ----------
    gap
        The held-out gap (a fraction) [-].
    min_gap
        The identification's floor, gap.min_gap [-].
    effect
        The step the test is applied to; "": the whole diagnosis.

    Returns
    -------
    test : Test
        The decision "above_floor".
    """
    ok = bool(gap >= min_gap)
    return Test(
        "above_floor",
        float(gap),
        float(min_gap),
        ok,
        f"the held-out gap {percent(gap)} is "
        + ("above" if ok else "below")
        + f" gap.min_gap {percent(min_gap)}"
        + (
            ""
            if ok
            else ": the identified model reproduces the records as well as the chain's own identification allows"
        ),
        effect,
    )


def beyond_scatter(gap: float, scatter: float, noise_factor: float, effect: str = "") -> Test:
    """Test whether the held-out gap is at least noise_factor x the records' scatter.

    Parameters
    ----------
    gap
        The held-out gap (a fraction) [-].
    scatter
        The records' bootstrap scatter of the held-out gap [-].
    noise_factor
        Factor on the scatter, gap.noise_factor [-].
    effect
        The step the test is applied to; "": the whole diagnosis.

    Returns
    -------
    test : Test
        The decision "beyond_scatter".
    """
    ok = bool(gap >= noise_factor * scatter)
    return Test(
        "beyond_scatter",
        float(gap),
        float(noise_factor * scatter),
        ok,
        f"the held-out gap {percent(gap)} is "
        + ("beyond" if ok else "within")
        + f" {noise_factor:g} x the records' scatter {percent(scatter, 2)}",
        effect,
    )


def shrinks_gap(effect: str, before: float, after: float, lower: float, min_reduction: float) -> Test:
    """Test whether the first effect shrinks the whole held-out gap by min_reduction.

    Its bootstrap interval's lower end (``lower``, of the reduction) must be above zero too.

    Parameters
    ----------
    effect
        The effect of the step.
    before
        The held-out gap before the step [-].
    after
        The held-out gap after it (after the pair's second half for a pair) [-].
    lower
        Lower end of the bootstrap interval of the reduction 1 - after / before [-].
    min_reduction
        The least reduction of the whole gap, gap.min_reduction [-].

    Returns
    -------
    test : Test
        The decision "shrinks_gap" (value the reduction 1 - after / before).
    """
    red = 1.0 - after / before if before > 0 and np.isfinite(after) else -np.inf
    ok = bool(red >= min_reduction and lower > 0)
    return Test(
        "shrinks_gap",
        float(red),
        float(min_reduction),
        ok,
        f"{effect} shrinks the held-out gap from {percent(before)} to {percent(after)} ({red:.1%})"
        + (
            ""
            if ok
            else f": less than gap.min_reduction {min_reduction:.0%} of it"
            + ("" if red < min_reduction else " with its bootstrap interval reaching zero")
        ),
        effect,
    )


def beyond_model_form(effect: str, after: float, alternatives: Sequence[str], form: Sequence[str]) -> Test:
    """Test whether a step is told apart from model-form error.

    It is where no form candidate (``form``) is among its alternatives, and, if its own effect is one, it has no
    alternatives.

    Parameters
    ----------
    effect
        The step's effect.
    after
        The held-out gap after the step [-].
    alternatives
        The candidates within gap.separation of the step (``verdict.indistinguishable``).
    form
        The form candidates' names (``Candidate.form``).

    Returns
    -------
    test : Test
        The decision "beyond_model_form" (value the rivals among the alternatives, "-" for none).
    """
    rivals = [a for a in alternatives if a in form]
    if effect in form and alternatives:
        rivals = list(alternatives)
    ok = not rivals
    return Test(
        "beyond_model_form",
        ", ".join(rivals) or "-",
        "-",
        ok,
        f"{effect} leaves {percent(after)}"
        + (
            ""
            if ok
            else f", and {' and '.join(rivals)} explain{'s' if len(rivals) == 1 else ''} the gap about as well: on "
            "these records it is not told apart from the base model's form (gap.separation)"
        ),
        effect,
    )


def resolution(
    before: float,
    form_after: Mapping[str, float],
    scatter: float,
    settings: GapSettings | Mapping[str, float],
    held: bool = True,
) -> dict:
    """Return the smallest change of the held-out gap these records attribute to a first effect.

    It must shrink the gap by min_reduction of it, beyond noise_factor x the scatter, and leave less than the best
    form candidate's gap (``form_after``) over gap.separation; below the floor (min_gap) no change is attributed
    (the whole gap).

    Parameters
    ----------
    before
        The held-out gap the candidates start from [-].
    form_after
        {candidate: held-out gap after it} of the form candidates [-]; non-finite gaps are left out.
    scatter
        The records' bootstrap scatter of the held-out gap [-].
    settings
        The gap settings (``GapSettings`` or a mapping of them): separation, min_reduction, min_gap and noise_factor
        are read, each [-].
    held
        Whether a load case is held out.

    Returns
    -------
    resolution : dict
        {heldout_gap (the smallest change, a fraction), form_heldout_gap, form_candidate (the best form candidate or
        None), how (a sentence saying which bound binds)}.
    """
    sep, min_red = setting(settings, "separation"), setting(settings, "min_reduction")
    min_gap, noise = setting(settings, "min_gap"), setting(settings, "noise_factor")
    finite = {k: float(v) for k, v in form_after.items() if np.isfinite(v)}
    best = min(finite, key=finite.get) if finite else None
    form_gap = min(before, finite[best]) if best else before
    if not held or before < min_gap:
        x = before
        how = (
            f"The held-out gap {percent(before)} is below the identification's floor gap.min_gap "
            f"{percent(min_gap)}: no change of it is attributed to an effect"
            if held
            else "No load case is held out: no change of the gap is attributed to an effect"
        )
    else:
        parts = {
            f"gap.min_reduction ({min_red:.0%}) of the held-out gap": min_red * before,
            f"{noise:g} x the records' scatter": noise * scatter,
            (
                f"what leaves less than {best} (the base model's form: {percent(form_gap)}) over gap.separation {sep:g}"
                if best
                else f"a gap over gap.separation {sep:g}"
            ): before - form_gap / sep,
        }
        key = max(parts, key=parts.get)
        x = float(parts[key])
        how = (
            f"An effect that changes the held-out gap ({percent(before)}) by less than {percent(x)} is not "
            f"distinguishable from model-form error on these records (binding: {key})"
        )
    return {"heldout_gap": float(x), "form_heldout_gap": float(form_gap), "form_candidate": best, "how": how}


def first_pass_best(rows: Sequence[Mapping], before: float) -> Test | None:
    """Return the decision naming the first pass's best candidate, where the explanation added no effect.

    That candidate did not shrink the held-out gap materially (``verdict.explains_materially``, applied by
    ``explain.explain``).

    Parameters
    ----------
    rows
        The first pass's ranking, each row with ``effect`` and ``heldout_gap_after``.
    before
        The held-out gap the candidates started from [-].

    Returns
    -------
    test : Test | None
        The failed decision "explains_materially" of the best candidate (least finite held-out gap after it); None
        without candidates.
    """
    finite = [r for r in rows if np.isfinite(r["heldout_gap_after"])]
    if not finite:
        return None
    best = min(finite, key=lambda r: r["heldout_gap_after"])
    return Test(
        "explains_materially",
        float(best["heldout_gap_after"]),
        float(before),
        False,
        f"no candidate shrinks the held-out gap materially (best: {best['effect']}, {percent(before)} -> "
        f"{percent(best['heldout_gap_after'])})",
        best["effect"],
    )
