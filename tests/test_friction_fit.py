"""The friction kernel against its reference, its guards, and the GA fit on known answers."""

import numpy as np
import pytest
from contactid.contact_laws import stiction_shear_stiffness
from contactid.friction import valanis_friction_force, valanis_friction_force_reference
from contactid.friction_fit import FitSettings, fit_friction_law

TRUE = np.array([3.857e7, 2.547e5, 1.0e4, 0.284, 0.397])
F0 = 54.375


def signals(m, t_shift=0.0):
    t = np.arange(m) / m + t_shift
    xi = 1e-5 * np.sin(2 * np.pi * t) + 3e-6 * np.sin(6 * np.pi * t + 0.3)
    n = 70 + 12 * np.sin(2 * np.pi * t + 0.5) + 4 * np.sin(6 * np.pi * t)
    return xi, n


def test_fast_kernel_agrees_with_reference():
    xi, n = signals(300)
    rng = np.random.default_rng(3)
    pop = TRUE * (0.7 + 0.6 * rng.random((6, 5)))
    pop[:, 3] = np.clip(pop[:, 3], 0, 0.9)
    fast = valanis_friction_force(xi, n, pop)
    ref = valanis_friction_force_reference(xi, n, pop)
    assert fast.shape == (6, 300)
    assert np.max(np.abs(fast - ref)) < 1e-9 * np.max(np.abs(ref))


def test_256_samples_per_period_within_half_percent():
    fine = valanis_friction_force(*signals(4096), TRUE[None])[0]
    coarse = valanis_friction_force(*signals(256), TRUE[None])[0]
    assert np.max(np.abs(coarse - fine[::16])) < 0.005 * np.max(np.abs(fine))


def test_periodic_steady_state_does_not_depend_on_start():
    xi, n = signals(512)
    S = valanis_friction_force(xi, n, TRUE[None])[0]
    S_rolled = valanis_friction_force(np.roll(xi, 100), np.roll(n, 100), TRUE[None])[0]
    assert np.max(np.abs(np.roll(S, 100) - S_rolled)) < 1e-5 * np.max(np.abs(S))
    assert np.max(S) == pytest.approx(0.397 * n.max(), rel=0.1)


@pytest.mark.parametrize(
    "xi_n_params, message",
    [
        (lambda xi, n: (xi, n, np.empty((0, 5))), "empty population"),
        (lambda xi, n: (xi, n - 80.0, TRUE[None]), "normal force reaches"),
        (lambda xi, n: (xi, n, np.array([[3e7, 2e5, 0, 1.2, 0.4]])), r"kappa must lie in \[0, 1\)"),
        (lambda xi, n: (xi * np.nan, n, TRUE[None]), "NaN"),
        (lambda xi, n: (xi, n, TRUE[None, :4]), r"shape \(n_sets, 5\)"),
    ],
)
def test_guards_give_clear_errors(xi_n_params, message):
    with pytest.raises(ValueError, match=message):
        valanis_friction_force(*xi_n_params(*signals(64)))


def coefficients(x, k=25):
    m = x.size
    return (2j * np.fft.fft(x)[1 : k + 1] / m)[None]


@pytest.fixture(scope="module")
def synthetic():
    xi, n = signals(2048)
    S = valanis_friction_force(xi, n, TRUE[None])[0]
    return coefficients(xi), coefficients(n - 70.0), coefficients(S)


@pytest.mark.slow  # three GA fits of the default size
def test_fit_recovers_known_parameters_reproducibly(synthetic):
    settings = FitSettings()
    a = fit_friction_law(*synthetic, F0, 70.0, settings, seed=5, n_harmonics_data=25)
    b = fit_friction_law(*synthetic, F0, 70.0, settings, seed=5, n_harmonics_data=25)
    c = fit_friction_law(*synthetic, F0, 70.0, settings, seed=6, n_harmonics_data=25)
    assert np.array_equal(a.params, b.params)
    assert a.params[4] == pytest.approx(0.397, rel=0.02)
    assert a.params[3] == pytest.approx(0.284, rel=0.10)
    e0 = stiction_shear_stiffness(70.0, TRUE[0], TRUE[1])
    assert a.e0_at_preload == pytest.approx(e0, rel=0.05)
    assert a.e0_interval[0] <= e0 <= a.e0_interval[1]
    for i in (3, 4):  # another seed lands inside the reported intervals
        assert a.intervals[i, 0] <= c.params[i] <= a.intervals[i, 1]
    assert len(a.logbook) == settings.generations
    assert a.logbook[-1][1] <= a.logbook[0][1]


@pytest.mark.slow
def test_bounds_that_exclude_the_truth_are_flagged(synthetic):
    settings = FitSettings(bounds=((1e6, 1e9), (1e4, 1e7), (0.0, 1e6), (0.0, 0.95), (0.05, 0.3)), generations=10)
    res = fit_friction_law(*synthetic, F0, 70.0, settings, seed=5, n_harmonics_data=25)
    assert any("mu" in w and "upper search bound" in w for w in res.warnings)
