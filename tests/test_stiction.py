import math

import numpy as np
import pytest

from contactid.beam_model import natural_frequencies
from contactid.parameters import StructureParameters
from contactid.stiction import frequency_sigma, stiction_stiffness


def test_recovers_k_t_and_bounds_k_n_from_exact_frequencies():
    p = StructureParameters(tangential_lever_arm=0.00458, youngs_modulus=2.164e11)
    truth = (1.43e7, 2.37e7)
    f = natural_frequencies(p.with_contact(*truth), 3)
    sigma = frequency_sigma(f, np.zeros(3), 1e-3)
    fit = stiction_stiffness(p, f, sigma)
    assert fit.k_t == pytest.approx(truth[0], rel=1e-3)
    assert fit.k_t_interval[0] < truth[0] < fit.k_t_interval[1]
    assert fit.k_n_interval[0] <= truth[1] <= fit.k_n_interval[1]


def test_rigid_normal_contact_gives_only_a_lower_bound():
    """With k_n far above what the frequencies can see, the data bound k_n only from below."""
    p = StructureParameters()
    f = natural_frequencies(p.with_contact(1e7, 1e10), 3)
    fit = stiction_stiffness(p, f, frequency_sigma(f, np.zeros(3), 1e-3))
    assert not fit.k_n_bounded_above
    assert math.isinf(fit.k_n_interval[1])
    assert 1e5 < fit.k_n_lower_bound < 1e10
    assert fit.k_t == pytest.approx(1e7, rel=5e-3)
