"""One story (gap/story.py): the verdict derived from the explanation, each decision a pure function with its trace,
on hand-made numbers (milliseconds). tests/gap/test_gap.py checks the same decisions on rig data."""

import pytest
from contactid.gap.story import one_story_holds, tell
from contactid.gap.story_decisions import held_out
from contactid.schema import schema_defaults

GAP = schema_defaults("gap")  # the config's defaults, from the schema (the hand-made numbers assume them)
SETTINGS = {key: GAP[key] for key in ("min_gap", "noise_factor", "min_reduction", "separation")}
PLACE = "tangential_contact"
FORM = ["structural_damping"]


def row(effect, after, before=0.02, acts_on=PLACE, low=None):
    """A first-pass ranking row as diagnose() builds it."""
    red = 1 - after / before
    return {
        "effect": effect,
        "acts_on": acts_on,
        "heldout_gap_after": after,
        "reduction": red,
        "reduction_interval": [red - 0.05 if low is None else low, red + 0.05],
    }


def step(effect, before, after, alternatives=(), **extra):
    return {
        "effect": effect,
        "parameters": {},
        "heldout_gap_before": before,
        "heldout_gap_after": after,
        "alternatives": list(alternatives),
        **extra,
    }


def story(steps, rows, before=0.02, scatter=1e-4, place=PLACE, n_held=2, **kw):
    return tell(
        steps, rows, before=before, scatter=scatter, place=place, settings=SETTINGS, form=FORM, n_held=n_held, **kw
    )


def trace_of(s):
    return [(t["test"], t["step"], t["passed"]) for t in s.trace]


def test_a_clean_step_is_the_verdict_and_the_trace_holds_every_test():
    rows = [row("viscous_friction", 0.002), row("structural_damping", 0.012)]
    s = story([step("viscous_friction", 0.02, 0.002)], rows)
    assert s.verdict == "viscous_friction"
    assert s.reason == "viscous_friction shrinks the held-out gap from 2 % to 0.2 % (99% of its power)"
    assert [x["kind"] for x in s.explanation] == ["effect"]
    assert s.explanation[0]["share"] == pytest.approx(1 - 0.01)
    assert trace_of(s) == [
        ("held_out", "", True),
        ("above_floor", "viscous_friction", True),
        ("beyond_scatter", "viscous_friction", True),
        ("shrinks_gap", "viscous_friction", True),
        ("beyond_model_form", "viscous_friction", True),
        ("acts_where_gap_lies", "viscous_friction", True),
    ]
    shrink = next(t for t in s.trace if t["test"] == "shrinks_gap")
    assert shrink["value"] == pytest.approx(0.9) and shrink["threshold"] == 0.5
    assert one_story_holds({"verdict": s.verdict, "explanation": s.explanation})


def test_a_step_the_base_models_form_explains_as_well_is_not_an_effect():
    # as on the other simulator's effect-free records (another friction law): a normal dashpot leaves 0.583 % of
    # 1.52 %, the beam modes' damping 0.645 %
    rows = [row("normal_contact_damping", 0.00583, 0.0152), row("structural_damping", 0.00645, 0.0152)]
    steps = [step("normal_contact_damping", 0.0152, 0.00583, ["viscous_friction", "structural_damping"])]
    s = story(steps, rows, before=0.0152, place="contact")
    assert s.verdict == "none" and s.explanation == []
    assert s.reason.startswith("normal_contact_damping leaves 0.583 %, and structural_damping explains the gap about")
    form = [t for t in s.trace if t["test"] == "beyond_model_form"][0]
    assert form["value"] == "structural_damping" and not form["passed"]
    assert one_story_holds({"verdict": s.verdict, "explanation": s.explanation})


def test_the_form_candidate_alone_is_an_effect_where_the_library_lists_it_and_model_form_where_it_does_not():
    rows = [row("structural_damping", 0.002), row("viscous_friction", 0.015)]
    steps = [step("structural_damping", 0.02, 0.002)]
    assert story(steps, rows).verdict == "structural_damping"
    left_out = story(steps, rows, model_form=FORM)
    assert left_out.verdict == "none" and [x["kind"] for x in left_out.explanation] == ["model_form"]
    assert one_story_holds({"verdict": "none", "explanation": left_out.explanation})
    # with an effect as well within separation, the form candidate's step is not told apart from it
    s = story([step("structural_damping", 0.02, 0.002, ["viscous_friction"])], rows)
    assert s.verdict == "none" and s.explanation == []


@pytest.mark.parametrize(
    "after, low, named",
    [(0.0102, None, False), (0.010, None, True), (0.002, 0.0, False), (0.002, -0.2, False), (0.002, 1e-3, True)],
)
def test_the_first_effect_shrinks_the_whole_gap_by_min_reduction_with_its_interval_above_zero(after, low, named):
    s = story([step("viscous_friction", 0.02, after)], [row("viscous_friction", after, low=low)])
    assert (s.verdict == "viscous_friction") is named
    if not named:
        assert s.explanation == [] and "shrinks the held-out gap from 2 %" in s.reason


def test_two_effects_count_where_one_of_them_acts_where_the_gap_lies():
    # a structural damping first and a preload drift (the records drift: place non_stationary)
    steps = [step("structural_damping", 0.05, 0.01), step("preload_drift", 0.01, 0.003)]
    rows = [row("structural_damping", 0.01, 0.05, acts_on="structure_or_measurement")]
    rows.append(row("preload_drift", 0.04, 0.05, acts_on="non_stationary"))
    s = story(steps, rows, before=0.05, place="non_stationary")
    assert s.verdict == "structural_damping" and [x["effect"] for x in s.explanation] == [
        "structural_damping",
        "preload_drift",
    ]
    alone = story(steps[:1], rows, before=0.05, place="non_stationary")
    assert alone.verdict == "none" and "the gap lies in non_stationary" in alone.reason


def test_a_first_effect_acting_elsewhere_than_the_gap_ends_the_explanation():
    rows = [row("normal_contact_damping", 0.001, acts_on="normal_contact")]
    s = story([step("normal_contact_damping", 0.02, 0.001)], rows)
    assert s.verdict == "none" and s.explanation == []
    assert "the gap lies in tangential_contact" in s.reason
    # "contact" (eta unobservable) admits either direction
    assert story([step("normal_contact_damping", 0.02, 0.001)], rows, place="contact").verdict == (
        "normal_contact_damping"
    )


def test_floor_and_scatter():
    s = story([step("viscous_friction", 0.0059, 0.0005)], [row("viscous_friction", 0.0005, 0.0059)], before=0.0059)
    assert s.verdict == "none" and "below gap.min_gap 0.6 %" in s.reason
    s = story([step("viscous_friction", 0.02, 0.002)], [row("viscous_friction", 0.002)], scatter=0.007)
    assert s.verdict == "none" and s.reason.startswith("the held-out gap 2 % is within 3 x the records' scatter 0.7 %")
    assert story([step("viscous_friction", 0.02, 0.002)], [row("viscous_friction", 0.002)], scatter=0.0066).verdict == (
        "viscous_friction"
    )


def test_equal_effects_are_one_step_with_its_alternatives():
    rows = [row("viscous_friction", 0.004), row("normal_contact_damping", 0.0059, acts_on="normal_contact")]
    s = story([step("viscous_friction", 0.02, 0.004, ["normal_contact_damping"])], rows)
    assert s.verdict == "viscous_friction" and s.reason.endswith("; or, as well, normal_contact_damping")


def test_a_later_step_near_the_base_models_form_is_left_out_and_said():
    steps = [
        step("channel_time_skew", 0.0883, 0.00978),
        step("viscous_friction", 0.00978, 0.00366, ["normal_contact_damping", "structural_damping"]),
    ]
    rows = [row("channel_time_skew", 0.00597, 0.0883, acts_on="structure_or_measurement")]
    s = story(steps, rows, before=0.0883, place="structure_or_measurement")
    assert s.verdict == "channel_time_skew" and [x["effect"] for x in s.explanation] == ["channel_time_skew"]
    assert "; then viscous_friction leaves 0.366 %, and structural_damping" in s.reason
    assert s.explanation[0]["share"] == pytest.approx(1 - (0.00978 / 0.0883) ** 2)


def test_the_largest_share_is_the_verdict():
    steps = [step("preload_drift", 0.02, 0.009, pair_first=True), step("normal_contact_damping", 0.009, 0.002)]
    rows = [row("preload_drift", 0.0125, acts_on="any")]  # alone 37.5 %: the pair is judged together
    s = story(steps, rows)
    assert [x["effect"] for x in s.explanation] == ["preload_drift", "normal_contact_damping"]
    assert s.verdict == "preload_drift"  # 0.02^2 - 0.009^2 > 0.009^2 - 0.002^2
    assert s.reason.endswith("; with normal_contact_damping")
    # without the pair flag, the first step alone is judged by its own 55 %
    assert story([dict(steps[0], pair_first=False), steps[1]], rows).verdict == "preload_drift"


def test_an_update_that_changes_nothing_is_no_step_and_one_that_names_an_effect_is_the_verdict():
    steps = [step("model_updating", 0.7391, 0.7613), step("viscous_friction", 0.7613, 0.70)]
    rows = [row("viscous_friction", 0.70, 0.7613, acts_on="structure_or_measurement")]
    s = story(steps, rows, before=0.7613, scatter=1e-4, place="structure_or_measurement")
    assert s.verdict == "none" and s.explanation == []
    assert ("update_counts", "model_updating", False) in trace_of(s)
    named = story(
        [step("model_updating", 0.05, 0.003)],
        [row("viscous_friction", 0.0029, 0.003)],
        before=0.003,
        update_effect=("transducer_mass_error", "model updating (...) takes the gap ..."),
    )
    assert named.verdict == "transducer_mass_error" and named.reason.startswith("model updating (...)")
    # the place is the updated model's: an update's effect alone is not tested against it
    elsewhere = story(
        [step("model_updating", 0.05, 0.003)],
        [row("transducer_mass_error", 0.04, 0.003, acts_on="structure_or_measurement")],
        before=0.003,
        place="contact",
        update_effect=("transducer_mass_error", "model updating (...) takes the gap ..."),
    )
    assert elsewhere.verdict == "transducer_mass_error"
    assert named.explanation[0]["names"] == "transducer_mass_error"
    # the update's effect counts for the place: a normal dashpot after it where the gap lies in the structure
    with_dashpot = story(
        [step("model_updating", 0.05, 0.01), step("normal_contact_damping", 0.01, 0.003)],
        [
            row("transducer_mass_error", 0.04, 0.05, acts_on="structure_or_measurement"),
            row("normal_contact_damping", 0.004, 0.01, acts_on="normal_contact"),
        ],
        before=0.01,
        place="structure_or_measurement",
        update_effect=("transducer_mass_error", "model updating (...) takes the gap ..."),
    )
    assert [x.get("names", x["effect"]) for x in with_dashpot.explanation] == [
        "transducer_mass_error",
        "normal_contact_damping",
    ]
    assert one_story_holds({"verdict": named.verdict, "explanation": named.explanation})
    plain = story([step("model_updating", 0.05, 0.003)], [row("viscous_friction", 0.0029, 0.003)], before=0.003)
    assert plain.verdict == "none" and [x["kind"] for x in plain.explanation] == ["update"]


def test_a_separation_law_that_never_opens_is_model_form_after_other_steps_and_an_effect_first():
    rows = [row("contact_separation", 0.002, acts_on="normal_contact")]
    # after an update (the compound benchmark's hardening rigs): a harder normal law, model form
    steps = [step("model_updating", 0.05, 0.02), step("contact_separation", 0.02, 0.008, contact_opens=False)]
    s = story(steps, rows, place="normal_contact")
    assert s.verdict == "none" and [x["kind"] for x in s.explanation] == ["update", "model_form"]
    assert s.reason == (
        "the explanation names no effect: its steps are model_updating (an update that names no effect), "
        "contact_separation (model form) (the explanation's steps take the held-out gap from 5 % to 0.8 %)"
    )
    # first (the blind benchmark's separating contacts): judged by the first effect's tests
    first = story([step("contact_separation", 0.02, 0.002, contact_opens=False)], rows, place="normal_contact")
    assert first.verdict == "contact_separation"
    assert one_story_holds({"verdict": first.verdict, "explanation": first.explanation})


def test_no_held_out_case_tells_nothing():
    s = story([step("viscous_friction", 0.02, 0.002)], [row("viscous_friction", 0.002)], n_held=0)
    assert s.verdict == "none" and s.explanation == [] and s.reason == held_out(0).says


def test_an_empty_explanation_names_the_first_pass_best_in_its_reason():
    s = story([], [row("viscous_friction", 0.015), row("structural_damping", 0.018)])
    assert s.verdict == "none"
    assert s.reason == "no candidate shrinks the held-out gap materially (best: viscous_friction, 2 % -> 1.5 %)"
    # below the floor, the floor says it
    low = story([], [row("viscous_friction", 0.0025, 0.003)], before=0.003)
    assert low.reason.startswith("the held-out gap 0.3 % is below gap.min_gap 0.6 %")
    assert low.trace[-1]["test"] == "above_floor" and not low.trace[-1]["passed"]


def test_one_story_holds_says_when_two_stories_are_told():
    ex = [{"effect": "viscous_friction", "kind": "effect", "share": 0.9}]
    assert one_story_holds({"verdict": "viscous_friction", "explanation": ex})
    assert not one_story_holds({"verdict": "none", "explanation": ex})
    assert not one_story_holds({"verdict": "structural_damping", "explanation": ex})
    assert one_story_holds({"verdict": "none", "explanation": [{"effect": "model_updating", "kind": "update"}]})
    assert not one_story_holds({"verdict": "records_disagree", "explanation": ex})
    assert one_story_holds({"verdict": "records_disagree", "explanation": []})
