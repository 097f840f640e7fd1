"""The isolability table (gap/isolability.py) on hand-made signatures."""

import numpy as np
import pytest
from contactid.gap.isolability import isolability, signature


def test_signature_is_the_change_of_the_held_out_residuals():
    before = {"lc2": np.array([1 + 1j, 0]), "lc3": np.array([2.0 + 0j])}
    after = {"lc2": np.array([1 + 2j, 1]), "lc3": np.array([1.0 + 0j])}
    np.testing.assert_allclose(signature(before, after, ["lc2", "lc3"]), [0, 1, 1, 0, -1, 0])


def test_pairs_alike_once_the_form_direction_is_removed():
    form = np.array([1.0, 0.0, 0.0])
    # a and b differ mostly along the form direction: alike once it is removed; c is orthogonal to both
    sigs = {
        "structural_damping": form,
        "a": np.array([5.0, 1.0, 0.05]),
        "b": np.array([-3.0, 1.0, 0.0]),
        "c": np.array([0.0, 0.0, 1.0]),
        "off": np.zeros(3),
    }
    out = isolability(sigs, ["structural_damping"])
    assert out["form_removed"] == ["structural_damping"]
    assert [p["candidates"] for p in out["pairs"]] == [["a", "b"]]
    assert out["pairs"][0]["cosine"] == pytest.approx(1 / np.hypot(1, 0.05))
    # without the form candidate, a and b point apart (cosine -0.88)
    assert (
        isolability({k: v for k, v in sigs.items() if k != "structural_damping"}, ["structural_damping"])["pairs"] == []
    )
