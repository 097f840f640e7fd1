"""One story: the verdict derived from the explanation, every decision a small pure function with its trace.

The explanation (``explain.explain``) adds effects while each shrinks what is left of the held-out gap materially;
the decisions (``story_decisions``) then say which of its steps the records attribute to an effect, in a fixed order:

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
reason sentence comes from the trace: the step's numbers, or the test that ended the explanation.
``story_decisions.resolution`` says what these records can attribute: the smallest change of the held-out gap a first
effect must make.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Mapping, Sequence

from .place import acts_where, never_opens
from .story_decisions import (
    Test,
    above_floor,
    acts_where_gap_lies,
    beyond_model_form,
    beyond_scatter,
    first_pass_best,
    held_out,
    shrinks_gap,
    update_counts,
)
from .verdict import gap_shares, percent, setting

if TYPE_CHECKING:
    from .settings import GapSettings


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
