"""Finite-difference Jacobians with absolute steps (contactid.finite_differences) against analytic ones."""

import numpy as np
from contactid.finite_differences import central_difference_jacobian, forward_difference_jacobian
from scipy.optimize import least_squares


def fun(x):
    return np.array([np.sin(3 * x[0]) + x[1] ** 2, np.exp(x[0] - x[1]), x[0] * x[1]])


def exact(x):
    return np.array([[3 * np.cos(3 * x[0]), 2 * x[1]], [np.exp(x[0] - x[1]), -np.exp(x[0] - x[1])], [x[1], x[0]]])


def test_central_differences_hold_their_step_at_zero_and_at_the_bounds():
    jac = central_difference_jacobian(fun, 1e-5)
    for x in (np.zeros(2), np.array([1e-9, -1e-7]), np.array([0.7, -1.3])):
        assert np.allclose(jac(x), exact(x), atol=1e-8)
    # one-sided (second order) where a step would leave the box
    bounded = central_difference_jacobian(fun, 1e-4, 0.0, 1.0)
    for x in (np.array([0.0, 1.0]), np.array([5e-5, 0.99995])):
        assert np.allclose(bounded(x), exact(x), atol=1e-6)


def test_scipys_relative_step_is_noise_where_the_absolute_one_is_not():
    # a residual with rounding of 1e-12 (an eigensolver's): at x = 1e-6 scipy's diff_step=1e-5 steps by 1e-11
    rng = np.random.default_rng(1)

    def noisy(x):
        return fun(x) + 1e-12 * rng.standard_normal(3)

    x = np.array([1e-6, 1e-6])
    relative = least_squares(noisy, x, jac="3-point", diff_step=1e-5, max_nfev=1).jac
    absolute = central_difference_jacobian(noisy, 1e-5)(x)
    assert np.abs(relative - exact(x)).max() > 1e-2
    assert np.abs(absolute - exact(x)).max() < 1e-5


def test_forward_differences_reuse_the_last_evaluation_and_turn_back_at_the_upper_bound():
    calls = []

    def counted(x):
        calls.append(np.array(x))
        return fun(x)

    f, jac = forward_difference_jacobian(counted, 1e-6, 0.0, 1.0)
    x = np.array([0.3, 1.0])
    f(x)
    J = jac(x)
    assert len(calls) == 3  # fun(x) once, one step per variable
    assert calls[2][1] < 1.0  # backward at the upper bound
    assert np.allclose(J, exact(x), atol=1e-5)
