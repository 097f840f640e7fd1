"""The noise / record-length study: its parameter table and the e_0 formula (the sweep as Snakemake jobs:
tests/workflow/test_noise_study.py)."""

import numpy as np
import pytest
from contactid.studies import e0_at, noise_study_table


def test_parameter_table_is_the_full_product_and_refuses_empty_or_bad_axes():
    t = noise_study_table({"noise_fractions": [0.001, 0.01], "record_samples": [8192], "seeds": [1, 2, 3]})
    assert list(t.columns) == ["noise_fraction", "record_samples", "seed"] and len(t) == 6
    assert t.iloc[0].tolist() == [0.001, 8192, 1] and t.iloc[-1].tolist() == [0.01, 8192, 3]
    assert len(noise_study_table(None)) == 5 * 2 * 3  # the defaults
    with pytest.raises(ValueError, match="noise_study.seeds is empty"):
        noise_study_table({"seeds": []})
    with pytest.raises(ValueError, match="at least 1024 samples"):
        noise_study_table({"record_samples": [100]})


def test_e0_is_eq22_and_tends_to_k_c_n_at_low_load():
    assert e0_at(3.857e7, 2.547e5, 70.0) == pytest.approx(3.857e7 * (1 - np.exp(-2.547e5 * 70.0 / 3.857e7)), rel=1e-14)
    assert e0_at(1e12, 2.0e5, 10.0) == pytest.approx(2.0e6, rel=1e-5)  # k_c N << e_f: e_0 -> k_c N
