"""The story's decisions (gap/story_decisions.py) on hand-made numbers (milliseconds): what the records can
attribute, the resolution."""

import pytest
from contactid.gap.story_decisions import resolution

SETTINGS = {"min_gap": 0.006, "noise_factor": 3.0, "min_reduction": 0.5, "separation": 1.5}  # the config's defaults


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
