"""Contact laws of the rig and of the identified model (Section 5).

The rig's linear contact springs are the small-amplitude limits of these laws:
k_t is the Valanis law's stiction stiffness e_0 at the static preload (Eq. 22)
and k_n the normal law's tangent stiffness at the preload.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np


@dataclass(frozen=True)
class ValanisParameters:
    """Modified Valanis law, Eqs. 21-22.

    Attributes
    ----------
    e_f
        Asymptotic stiction stiffness e_f of Eq. 22 [N/m].
    k_c
        Rate k_c at which the stiction stiffness approaches e_f with the normal force (Eq. 22) [1/m].
    e_t
        Tangent stiffness e_t of the law in gross slip [N/m].
    kappa
        Valanis parameter kappa [-].
    mu
        Friction coefficient mu [-].
    """

    e_f: float
    k_c: float
    e_t: float
    kappa: float
    mu: float

    @classmethod
    def from_config(cls, c: Mapping[str, Any]) -> "ValanisParameters":
        """Read the law from a config mapping.

        Parameters
        ----------
        c
            The law's config block (the rig's ``rig.truth.friction``): keys ``e_f_n_per_m`` [N/m], ``k_c_per_m``
            [1/m], ``e_t_n_per_m`` [N/m], ``kappa`` [-] and ``mu`` [-]; other keys (``regularization``) are ignored.

        Returns
        -------
        parameters : ValanisParameters
            The law with those values.
        """
        return cls(
            float(c["e_f_n_per_m"]), float(c["k_c_per_m"]), float(c["e_t_n_per_m"]), float(c["kappa"]), float(c["mu"])
        )


def stiction_shear_stiffness(normal_force: float | np.ndarray, e_f: float, k_c: float) -> float | np.ndarray:
    """Return the contact shear stiffness at stiction, e_0 = e_f (1 - exp(-k_c N / e_f)) (Eq. 22).

    Parameters
    ----------
    normal_force
        Total normal force N [N], compression positive: a float, or an array of any shape (shape (n_forces,) for a
        sweep of forces).
    e_f
        Asymptotic stiction stiffness e_f [N/m].
    k_c
        Rate k_c of Eq. 22 [1/m].

    Returns
    -------
    stiffness : float | np.ndarray
        Stiction stiffness e_0 [N/m]: a float for a float ``normal_force``, else an array of its shape (shape
        (n_forces,) for a sweep).
    """
    from .friction import initial_stiffness  # the one implementation of Eq. 22 (compiled; the kernels call it)

    n = np.asarray(normal_force, dtype=float)
    return (
        initial_stiffness(float(n), float(e_f), float(k_c))
        if n.ndim == 0
        else initial_stiffness(n, float(e_f), float(k_c))
    )


@dataclass(frozen=True)
class NormalLaw:
    """Hardening normal contact law around the preload (compression positive).

    The law is

        N(eta) = N0 * ((delta0 - eta) / delta0)^p  for eta < delta0, 0 otherwise,

    with delta0 = p N0 / k_n the static approach, so that dN/d(-eta) = k_n at eta = 0.
    eta (m) is positive when the contact opens (Eq. 8).

    Attributes
    ----------
    preload
        Static normal preload N0 [N].
    stiffness_at_preload
        Tangent normal stiffness k_n at the preload [N/m].
    exponent
        Hardening exponent p [-].
    """

    preload: float
    stiffness_at_preload: float
    exponent: float

    @property
    def static_approach(self) -> float:
        """Static approach delta0 = p N0 / k_n.

        Returns
        -------
        static_approach : float
            Static approach delta0 [m].
        """
        return self.exponent * self.preload / self.stiffness_at_preload

    def normal_force(self, eta: float | np.ndarray) -> float | np.ndarray:
        """Return the total normal force N at the normal gap change eta; zero once the contact opens.

        Parameters
        ----------
        eta
            Normal gap change eta [m], positive when the contact opens: a float, or an array of any shape (shape
            (n_t,) for a time series).

        Returns
        -------
        normal_force : float | np.ndarray
            Total normal force N [N], compression positive: a float (numpy's) for a float ``eta``, else an array of
            its shape (shape (n_t,) for a time series).
        """
        d0 = self.static_approach
        c = np.clip((d0 - np.asarray(eta)) / d0, 0.0, None)
        return self.preload * c**self.exponent
