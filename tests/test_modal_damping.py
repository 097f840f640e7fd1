"""The identified model's damping of every mode (modal_damping.py): the identified ratios' trend carried on above
the identified modes, against the rig's own damping forms."""

import numpy as np
import pytest
from contactid.beam_model import assemble
from contactid.rig.nonlinear import reduced_model
from structures import configured_structure

P = configured_structure(tangential_lever_arm=0.00458, youngs_modulus=2.164e11, k_t=1.4276e7, k_n=2.37e7, n_elements=24)


def test_damping_above_the_identified_modes_grows_as_the_identified_ratios_do():
    """The identified model's damping of the modes the random test does not measure (higher beam modes, the static
    contact shapes) against the rig's own damping forms (rig.damping) and Rayleigh damping: a
    stiffness-proportional or Rayleigh-damped structure's ratios grow with f, and the model extrapolates them from
    three identified modes to every higher mode of the rig's reduced model within 1 % (the ceiling at 2
    included); a modal one keeps the last ratio (bit for bit the former rule), and a mass-proportional one, whose
    ratios fall with frequency, too."""
    from contactid.modal_damping import damping_by_mode, damping_exponent
    from contactid.rig.damping import damping_ratios

    model = assemble(P)
    red = reduced_model(model, 8)
    f = red.omega / (2 * np.pi)
    beam = np.flatnonzero(red.beam_mode)
    assert f[beam[-1]] > 5 * f[beam[2]]  # the static contact shapes lie far above the third mode
    for form, exact in (("stiffness_proportional", True), ("modal", True), ("mass_proportional", False)):
        truth = damping_ratios(f, 0.005, form, reference_hz=f[beam[0]])
        zeta = damping_by_mode(red.beam_mode, truth[beam[:3]], f)
        gamma = damping_exponent(f[beam[:3]], truth[beam[:3]])
        if exact:
            assert np.allclose(zeta[beam], truth[beam], rtol=0.01), form
        else:  # falling ratios are not extrapolated: the last identified one above
            assert gamma == 0.0 and np.all(zeta[beam[3:]] == truth[beam[2]])
        assert np.array_equal(damping_by_mode(red.beam_mode, truth[beam[:3]])[beam[:3]], truth[beam[:3]])
    # Rayleigh damping (alpha M + beta K, as many FE simulators damp): the mass term dominates the first mode, the
    # stiffness term the third; the fitted Rayleigh trend carries on within 1 %, where the power law alone (its
    # slope over the identified modes under 1) would damp the static contact shapes several times too little
    w = red.omega
    alpha, beta = 2 * 0.004 * w[beam[0]], 2 * 0.004 / w[beam[2]]
    truth = alpha / (2 * w) + beta * w / 2
    zeta = damping_by_mode(red.beam_mode, truth[beam[:3]], f)
    assert np.allclose(zeta[beam], np.minimum(truth[beam], 2.0), rtol=0.01)
    power_law = truth[beam[2]] * (f[beam[-1]] / f[beam[2]]) ** damping_exponent(f[beam[:3]], truth[beam[:3]])
    assert power_law < 0.5 * truth[beam[-1]]
    assert damping_exponent(f[beam[:3]], 0.005 * f[beam[:3]] / f[beam[0]]) == pytest.approx(1.0)
    assert damping_exponent(f[beam[:1]], [0.005]) == 0.0  # one mode tells no trend
    # the ceiling: ratios that would exceed 2 stay at 2
    steep = damping_by_mode(red.beam_mode, 0.2 * f[beam[:3]] / f[beam[0]], f)
    assert steep.max() == pytest.approx(2.0) and np.all(steep <= 2.0)
