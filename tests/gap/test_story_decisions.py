"""The story's decisions (gap/story_decisions.py) on hand-made numbers (milliseconds): what the records can
attribute, the resolution."""

import pytest
from contactid.gap.story_decisions import resolution
from contactid.schema import schema_defaults

GAP = schema_defaults("gap")  # the config's defaults, from the schema (the hand-made numbers assume them)
SETTINGS = {key: GAP[key] for key in ("min_gap", "noise_factor", "min_reduction", "separation")}


def test_resolution():
    # the form candidate leaves 0.839 % of 1.49 %: an effect must leave less than 0.839 / 1.5
    r = resolution(0.0149, {"structural_damping": 0.00839}, 1e-4, SETTINGS)
    assert r["heldout_gap"] == pytest.approx(0.0149 - 0.00839 / 1.5)
    assert r["form_candidate"] == "structural_damping" and "by less than 0.931 %" in r["how"]
    # a form candidate that explains nothing: min_reduction binds
    r = resolution(0.0148, {"structural_damping": 0.0174}, 1e-4, SETTINGS)
    assert r["heldout_gap"] == pytest.approx(0.5 * 0.0148) and "gap.min_reduction" in r["how"]
    # at the floor, or with nothing held out, no change is attributed
    assert resolution(0.005, {}, 1e-4, SETTINGS)["heldout_gap"] == 0.005
    assert resolution(0.02, {}, 1e-4, SETTINGS, held=False)["heldout_gap"] == 0.02
