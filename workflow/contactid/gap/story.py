"""One story: the verdict derived from the explanation, every decision a small pure function with its trace.

The explanation (``explain.explain``) adds effects while each shrinks what is left of the held-out gap materially;
the decisions here then say which of its steps the records attribute to an effect, in a fixed order:

1. ``held_out``: a load case is held out (otherwise every gap is the calibration case's own, which any refit lowers);
2. ``update_counts``: an accepted model update is a step only where it shrinks the held-out gap beyond the records'
   scatter (an update the random test accepts that changes the records' gap by nothing explains none of it);
3. for the first effect step, the tests a single effect's verdict has always had: the gap is above the
   identification's floor (``above_floor``) and beyond
   the records' scatter (``beyond_scatter``), the step (with the second half of a pair) shrinks the whole gap by
   gap.min_reduction with its bootstrap interval above zero (``shrinks_gap``);
4. for every effect step, ``beyond_model_form``: the candidates that change the base model's form rather than add an
   effect (``Candidate.form``: the beam modes' damping) are the reference of what model-form differences leave on
   these records; a step whose alternatives (the candidates within gap.separation of it, ``verdict.indistinguishable``)
   include such a candidate is not told apart from model-form error, and the explanation ends before it;
5. ``acts_where_gap_lies``: one of the explanation's effects acts where the localisation puts the gap (it names one
   place; where none acts there, the effects are dropped);
6. a contact-separation step whose law never opened, after other steps, stands for a stiffer or harder normal law
   (model form): kept, as ``kind`` "model_form", never the verdict. As the explanation's first step it is judged as
   an effect by the first effect's tests: it must take half of the identified model's whole held-out gap, acting
   where the gap lies (the blind benchmark's separating contacts: 170-290 % taken to 15-40 % by a law whose simulated
   N stays above the open limit; the compound benchmark's hardening rigs: 0.7-3.3 % taken to 0.3-0.8 % after an
   update or another effect).

The verdict is the effect of the explanation's effect step with the largest share, or "none" exactly when no step is
an effect (an update is not one, unless it amounts to one effect of the library, ``explain.updating_verdict``). The
reason sentence comes from the trace: the step's numbers, or the test that ended the explanation. ``resolution`` says
what these records can attribute: the smallest change of the held-out gap a first effect must make.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

from .verdict import acts_where, gap_shares, never_opens, percent, setting

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
        Whether one of them acts there, when several; None: ``verdict.acts_where(acts_on, place)``.

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


@dataclass
class Story:
    """What ``tell`` derives.

    Attributes
    ----------
    verdict
        The verdict: an effect or "none".
    reason
        Its reason sentence.
    explanation
        The explanation's steps kept (each with its ``kind`` and ``share``).
    trace
        The trace of the decisions (``Test.as_dict``).
    """

    verdict: str
    reason: str
    explanation: list
    trace: list = field(default_factory=list)


def _step_kind(step: Mapping, update_effect: str | None, model_form: Sequence[str] = (), first: bool = False) -> str:
    """Return the step's kind: "update", "model_form" or "effect".

    "update" is model updating that names no effect, "model_form" a form candidate the library in use leaves out (or a
    separation law that never opened, after other steps). ``first``: the explanation's first step.
    """
    if step.get("effect") == "model_updating":
        return "effect" if update_effect else "update"
    if step.get("effect") in model_form or (never_opens(step) and not first):
        return "model_form"
    return "effect"


def tell(  # noqa: C901
    steps: Sequence[Mapping],
    rows: Sequence[Mapping],
    *,
    before: float,
    scatter: float,
    place: str,
    settings: GapSettings | Mapping[str, float],
    form: Sequence[str],
    n_held: int,
    model_form: Sequence[str] = (),
    update_effect: tuple[str, str] | None = None,
) -> Story:
    """Derive the verdict, its reason and the explanation the records support.

    Decisions in the module's order; shares recomputed on what is kept.

    Parameters
    ----------
    steps
        The explanation's steps (model updating's step first where accepted), each with ``effect``,
        ``heldout_gap_before``, ``heldout_gap_after`` and where they apply ``alternatives``, ``pair_first``.
    rows
        The first pass's ranking, each row with effect, acts_on, reduction_interval and heldout_gap_after.
    before
        The held-out gap the candidates started from (the updated model's) [-].
    scatter
        The records' bootstrap scatter of it [-].
    place
        Where the localisation puts the gap.
    settings
        The gap settings (``GapSettings`` or a mapping of them): noise_factor, min_gap and min_reduction are read,
        each [-].
    form
        The form candidates' names.
    n_held
        How many load cases are held out.
    model_form
        The form candidates the library in use leaves out, never an effect.
    update_effect
        (effect, why) where the accepted update amounts to one effect of the library and explains most of the gap;
        None otherwise.

    Returns
    -------
    story : Story
        The verdict, its reason, the steps kept and the trace.
    """
    trace: list[Test] = []
    kept: list[dict] = []
    t = held_out(n_held)
    trace.append(t)
    if not t.passed:
        return Story("none", t.says, [], [x.as_dict() for x in trace])
    by_row = {r["effect"]: r for r in rows}
    ended: Test | None = None
    first_effect = True
    for s in steps:
        step = dict(s)
        name = step["effect"]
        if name == "model_updating":
            t = update_counts(
                step["heldout_gap_before"], step["heldout_gap_after"], scatter, setting(settings, "noise_factor")
            )
            trace.append(t)
            if t.passed:
                kind = _step_kind(step, update_effect[0] if update_effect else None)
                step["kind"] = kind
                if kind == "effect":
                    step["names"] = update_effect[0]
                    first_effect = False
                kept.append(step)
            continue
        kind = _step_kind(step, None, model_form, first=s is steps[0])
        tests: list[Test] = []
        if kind == "effect" and first_effect:
            row = by_row.get(name, {})
            g0 = float(step["heldout_gap_before"])
            after = float(step["heldout_gap_after"])
            if step.get("pair_first"):  # judged with its pair's second half: together they shrink the gap
                nxt = steps[list(steps).index(s) + 1]
                after = float(nxt["heldout_gap_after"])
            lower = float((row.get("reduction_interval") or [1.0])[0]) if not step.get("pair_first") else 1.0
            tests += [
                above_floor(g0, setting(settings, "min_gap"), name),
                beyond_scatter(g0, scatter, setting(settings, "noise_factor"), name),
                shrinks_gap(name, g0, after, lower, setting(settings, "min_reduction")),
            ]
        if kind == "effect":
            tests.append(beyond_model_form(name, step["heldout_gap_after"], step.get("alternatives") or [], form))
        trace.extend(tests)
        failed = next((x for x in tests if not x.passed), None)
        if failed is not None:
            ended = failed
            break
        step["kind"] = kind
        if kind == "effect":
            first_effect = False
        kept.append(step)
    # the localisation names one place: an explanation's effects are kept where one of them acts there (the first
    # effect alone judged so, two-effect records whose place followed the second lost both)
    # the place is localised on the model the candidates start from (the updated one): an update's effect is not
    # tested against it, but counts for the effects after it
    named = [x for x in kept if x["kind"] == "effect" and x["effect"] != "model_updating"]
    if named:
        effects_named = [x.get("names", x["effect"]) for x in kept if x["kind"] == "effect"]
        t = acts_where_gap_lies(
            " or ".join(effects_named),
            " | ".join(by_row.get(e, {}).get("acts_on", "any") for e in effects_named),
            place,
            any(acts_where(by_row.get(e, {}).get("acts_on", "any"), place) for e in effects_named),
        )
        trace.append(t)
        if not t.passed:
            first = kept.index(named[0])
            kept, ended = kept[:first], t
    # the shares start from the first kept step's gap (the chain's model where the update is a step)
    start = float(kept[0]["heldout_gap_before"]) if kept else before
    for s_, share in zip(kept, gap_shares(start, [float(x["heldout_gap_after"]) for x in kept])[0]):
        s_["share"] = share
    effects = [s for s in kept if s["kind"] == "effect"]
    if not effects and ended is None and kept:  # steps, none of them an effect
        steps_said = ", ".join(
            f"{x['effect']} ({'model form' if x['kind'] == 'model_form' else 'an update that names no effect'})"
            for x in kept
        )
        return Story(
            "none",
            f"the explanation names no effect: its steps are {steps_said}" + _left(kept, start),
            kept,
            [x.as_dict() for x in trace],
        )
    if not effects and ended is None:  # the explanation added no step: the floor, or its first pass's best
        t = above_floor(before, setting(settings, "min_gap"))
        t = t if not t.passed else first_pass_best(rows, before)
        if t is not None:
            trace.append(t)
            ended = t
    if not effects:
        reason = (ended.says if ended else "the explanation names no effect") + _left(kept, start)
        return Story("none", reason, kept, [x.as_dict() for x in trace])
    top = max(effects, key=lambda s: s["share"])
    verdict = top.get("names", top["effect"])
    if top["effect"] == "model_updating":
        reason = update_effect[1]
    else:
        alts = top.get("alternatives") or []
        reason = (
            f"{top['effect']} shrinks the held-out gap from {percent(top['heldout_gap_before'])} to "
            f"{percent(top['heldout_gap_after'])} ({top['share']:.0%} of its power)"
            + (f"; or, as well, {' or '.join(alts)}" if alts else "")
        )
    others = [s.get("names", s["effect"]) for s in effects if s is not top]
    if others:
        reason += f"; with {', '.join(others)}"
    if ended is not None:
        reason += f"; then {ended.says}"
    return Story(verdict, reason, kept, [x.as_dict() for x in trace])


def _left(kept: Sequence[Mapping], start: float) -> str:
    return (
        ""
        if not kept
        else f" (the explanation's steps take the held-out gap from {percent(start)} to "
        f"{percent(kept[-1]['heldout_gap_after'])})"
    )


def effect_steps(explanation: Sequence[Mapping]) -> list:
    """Return the explanation's steps that name an effect.

    Those of kind "effect" (an update only where it names one, ``names``); model form and an update that names none
    are not effects.

    Parameters
    ----------
    explanation
        The explanation's steps (diagnosis.json's ``explanation``).

    Returns
    -------
    steps : list
        The steps that name an effect, in order.
    """
    return [
        s
        for s in explanation
        if s.get("kind", "effect") == "effect" and (s.get("effect") != "model_updating" or s.get("names"))
    ]


def one_story_holds(diagnosis: Mapping) -> bool:
    """Check whether a diagnosis.json tells one story.

    Its verdict is the effect of the explanation's effect step with the largest share (an update that names an effect
    by that name), "none" exactly when no step is an effect; records that disagree (verdict records_disagree) have no
    explanation.

    Parameters
    ----------
    diagnosis
        The diagnosis (diagnosis.json's content): ``verdict`` and ``explanation`` are read.

    Returns
    -------
    holds : bool
        Whether it tells one story.
    """
    steps = diagnosis.get("explanation") or []
    verdict = diagnosis.get("verdict")
    if verdict == "records_disagree":
        return not steps
    effects = effect_steps(steps)
    if not effects:
        return verdict == "none"
    top = max(effects, key=lambda s: s.get("share", 0.0))
    return verdict == top.get("names", top["effect"])
