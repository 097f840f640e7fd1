"""The kernels' drive: sine and cosine from one libm call give the digits of np.sin and np.cos."""

import platform

import numpy as np
import pytest
from contactid.rig.integrator import _excitation
from contactid.sincos import HAS_LIBM_SINCOS, sin_cos

GLIBC = platform.libc_ver()[0] == "glibc"


def _angles():
    rng = np.random.default_rng(3)
    # a drive's angles h w t: up to 5 harmonics of 55 Hz over minutes of record, and small and negative ones
    return np.concatenate(
        [rng.uniform(0.0, 5 * 2 * np.pi * 55.0 * 120.0, 20000), rng.uniform(-10.0, 10.0, 5000), [0.0, 1e-300, np.pi]]
    )


@pytest.mark.skipif(not (GLIBC and HAS_LIBM_SINCOS), reason="GNU libm's sincos only")
def test_sin_cos_equals_sine_and_cosine_to_the_last_digit():
    x = _angles()
    got = np.array([sin_cos(v) for v in x])
    assert np.array_equal(got[:, 0], np.sin(x))
    assert np.array_equal(got[:, 1], np.cos(x))


def test_the_drive_is_the_sum_of_its_harmonics_in_order():
    """f(t) = sum_h f_sin sin(h w t) + f_cos cos(h w t), each term added in harmonic order, sine first: the same
    digits whichever terms are zero (a dual-sine drive has sines only, a record's drive both)."""
    w = 2 * np.pi * 54.4
    f_sin = np.array([7.5, 0.0, 1.2, 0.3, 0.0])
    f_cos = np.array([0.4, 0.2, 0.0, -0.1, 0.0])
    for t in np.linspace(0.0, 3.0, 997):
        expected = 0.0
        for k in range(5):
            if f_sin[k] != 0.0:
                expected += f_sin[k] * np.sin((k + 1.0) * w * t)
            if f_cos[k] != 0.0:
                expected += f_cos[k] * np.cos((k + 1.0) * w * t)
        assert _excitation(f_sin, f_cos, w, t) == expected
