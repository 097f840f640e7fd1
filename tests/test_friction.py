import numpy as np
import pytest
from contactid.contact_laws import NormalLaw, stiction_shear_stiffness
from contactid.friction import SINGULAR_GUARD, slip_limit_flag, valanis_friction_force, valanis_slope, valanis_step
from scipy.integrate import solve_ivp

P = (3.857e7, 2.547e5, 1.0e4, 0.284, 0.397)  # e_f, k_c, e_t, kappa, mu (Table 4, e_t small)


def march(xi, n, S=0.0, slip_limit=False):
    out = [S]
    for k in range(1, len(xi)):
        S = valanis_step(S, xi[k - 1], xi[k], n[k - 1], n[k], *P, 1e-6, slip_limit)
        out.append(S)
    return np.array(out)


def test_initial_slope_is_e0_of_eq22():
    e0 = stiction_shear_stiffness(70.0, P[0], P[1])
    assert e0 == pytest.approx(1.4276e7, rel=1e-3)
    assert valanis_slope(0.0, 0.0, 1.0, 70.0, *P) == pytest.approx(e0 * (1 + 0.0), rel=1e-9)


def test_monotonic_loading_saturates_at_mu_n():
    xi = np.linspace(0, 2e-5, 4001)
    S = march(xi, np.full_like(xi, 70.0))
    assert S[1] / xi[1] == pytest.approx(stiction_shear_stiffness(70.0, P[0], P[1]), rel=1e-3)
    assert S[-1] == pytest.approx(0.397 * 70.0 + P[2] * xi[-1], rel=2e-3)
    assert np.all(np.diff(S) >= 0)


def test_cycle_dissipates_energy_and_follows_normal_force():
    t = np.linspace(0, 2, 8001)
    xi = 5e-6 * np.sin(2 * np.pi * t)
    S = march(xi, np.full_like(xi, 70.0))
    last = t >= 1
    work = np.trapezoid(S[last], xi[last])
    assert work > 0  # hysteresis loop is walked so that the contact dissipates
    S_low = march(xi, np.full_like(xi, 35.0))
    assert np.max(np.abs(S_low[last])) < np.max(np.abs(S[last]))


def test_open_contact_carries_no_friction():
    for slip_limit in (False, True):
        assert valanis_step(5.0, 0.0, 1e-6, 70.0, 0.0, *P, 1e-6, slip_limit) == 0.0


def test_falling_normal_force_slip_limit_clamps_at_once_the_printed_law_relaxes_with_motion():
    # slip_limit: S is pulled back to the friction limit without motion
    assert valanis_step(27.0, 0.0, 0.0, 70.0, 30.0, *P, 1e-6, True) == pytest.approx(0.397 * 30.0, rel=1e-3)
    # as printed: no motion, no change; moving on, S relaxes monotonically onto the new macro-slip asymptote
    assert valanis_step(27.0, 0.0, 0.0, 70.0, 30.0, *P, 1e-6, False) == 27.0
    xi = np.linspace(0.0, 2e-5, 4001)
    S = march(xi, np.full_like(xi, 30.0), S=27.0)
    assert np.all(np.diff(S - P[2] * xi) <= 1e-12) and np.all(np.isfinite(S))
    assert S[-1] == pytest.approx(0.397 * 30.0 + P[2] * xi[-1], rel=2e-3)
    # beyond the singular point (|S - e_t xi| = alpha_0 / kappa = 42 N at N = 30 N) only the guard acts
    S = march(xi, np.full_like(xi, 30.0), S=80.0)
    assert S[1] <= SINGULAR_GUARD * 0.397 * 30.0 / 0.284 * (1 + 1e-9) and np.all(np.isfinite(S))
    assert S[-1] == pytest.approx(0.397 * 30.0 + P[2] * xi[-1], rel=2e-3)


def test_regularization_names_are_checked():
    assert slip_limit_flag("slip_limit") and not slip_limit_flag("none")
    with pytest.raises(ValueError, match="friction.regularization"):
        slip_limit_flag("clamp")


def printed_law_fine(xi_of, dxi_of, n_of, periods=6):
    """Eq. 21 as printed, integrated in time by an adaptive Runge-Kutta method (independent of the kernel):
    dS/dt = dS/dxi (S, xi, sgn xi', N) xi'(t), over several periods; S over the last one at t in [0, 1)."""

    def rhs(t, y):
        v = dxi_of(t)
        if v == 0.0:
            return [0.0]
        return [valanis_slope.py_func(y[0], xi_of(t), np.sign(v), n_of(t), *P) * v]

    t_eval = periods - 1 + np.arange(4096) / 4096
    sol = solve_ivp(rhs, (0.0, periods), [0.0], method="RK45", rtol=1e-9, atol=1e-9, t_eval=t_eval, max_step=1e-3)
    return sol.y[0]


@pytest.mark.parametrize("amp, dn", [(1e-5, 17.5), (3e-5, 17.5), (1e-5, -17.5)])
def test_kernel_agrees_with_an_independent_integration_of_eq21_as_printed(amp, dn):
    """N varies by +-25 % of the 70 N preload; the kernel on 1024 points per period within 0.2 % of max|S|."""
    w = 2 * np.pi
    xi_of = lambda t: amp * np.sin(w * t) + 0.3 * amp * np.sin(3 * w * t + 0.3)  # noqa: E731
    dxi_of = lambda t: amp * w * np.cos(w * t) + 0.9 * amp * w * np.cos(3 * w * t + 0.3)  # noqa: E731
    n_of = lambda t: 70.0 + dn * np.sin(w * t + 0.5)  # noqa: E731
    fine = printed_law_fine(xi_of, dxi_of, n_of)
    t = np.arange(1024) / 1024
    S = valanis_friction_force(xi_of(t), n_of(t), np.array([P]))[0]
    scale = np.max(np.abs(fine))
    assert np.max(np.abs(S - fine[::4])) < 0.002 * scale
    clamped = valanis_friction_force(xi_of(t), n_of(t), np.array([P]), regularization="slip_limit")[0]
    assert np.max(np.abs(clamped - fine[::4])) > 0.005 * scale  # the readings differ on such drives


def test_slip_limit_reproduces_the_kernel_of_issues_2_to_14():
    """Values of the clamped kernel before the law as printed became the default (commit e9264b5)."""
    m = 512
    t = np.arange(m) / m
    xi = 1e-5 * np.sin(2 * np.pi * t) + 3e-6 * np.sin(6 * np.pi * t + 0.3)
    n = 70 + 17.5 * np.sin(2 * np.pi * t + 0.5) + 4 * np.sin(6 * np.pi * t)
    rng = np.random.default_rng(3)
    pop = np.array(P) * (0.7 + 0.6 * rng.random((6, 5)))
    pop[:, 3] = np.clip(pop[:, 3], 0, 0.9)
    S = valanis_friction_force(xi, n, pop, regularization="slip_limit")[0, ::64]
    before = [22.94270705, 26.0456307, 1.95699712, 17.67017382, -18.50715292, -14.91973332, 0.28516249, -13.29930496]
    assert S == pytest.approx(before, rel=1e-8, abs=1e-8)


def test_normal_law_tangent_and_separation():
    law = NormalLaw(70.0, 2.37e7, 1.5)
    d = 1e-9
    k = -(law.normal_force(d) - law.normal_force(-d)) / (2 * d)
    assert k == pytest.approx(2.37e7, rel=1e-6)
    assert law.normal_force(0.0) == pytest.approx(70.0)
    assert law.normal_force(law.static_approach * 1.01) == 0.0
