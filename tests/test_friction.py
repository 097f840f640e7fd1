import numpy as np
import pytest

from contactid.contact_laws import NormalLaw, stiction_shear_stiffness
from contactid.friction import valanis_slope, valanis_step

P = (3.857e7, 2.547e5, 1.0e4, 0.284, 0.397)  # e_f, k_c, e_t, kappa, mu (Table 4, e_t small)


def march(xi, n, S=0.0):
    out = [S]
    for k in range(1, len(xi)):
        S = valanis_step(S, xi[k - 1], xi[k], n[k - 1], n[k], *P, 1e-6)
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
    assert valanis_step(5.0, 0.0, 1e-6, 70.0, 0.0, *P, 1e-6) == 0.0
    # falling normal force pulls S back to the friction limit
    assert valanis_step(27.0, 0.0, 0.0, 70.0, 30.0, *P, 1e-6) == pytest.approx(0.397 * 30.0, rel=1e-3)


def test_normal_law_tangent_and_separation():
    law = NormalLaw(70.0, 2.37e7, 1.5)
    d = 1e-9
    k = -(law.normal_force(d) - law.normal_force(-d)) / (2 * d)
    assert k == pytest.approx(2.37e7, rel=1e-6)
    assert law.normal_force(0.0) == pytest.approx(70.0)
    assert law.normal_force(law.static_approach * 1.01) == 0.0
