"""The identified model (the "sim") and the effects an augmentation adds to it.

The identified model is the chain's own result: the structure of ``structure`` with the linear
chain's k_t and k_n and its modal damping ratios, the friction law fitted by the chain
(Eqs. 21-22) and the normal law of Eq. 13 with the sign of our derivation, N = N0 - k_n eta
(linear and bilateral, as the paper identifies it). Its forward simulation under a record's measured
force is ``simulation``'s.

An augmentation (``Augmentation``) adds one or more physical effects to it; the candidate
library (``candidates``) maps an effect's few parameters onto these fields.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import lru_cache
from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from ..beam_model import FEModel, assemble
from ..friction_parameters import fitted_parameters
from ..parameters import StructureParameters, identified_structure
from ..rig.nonlinear import ReducedModel, reduced_model


@dataclass(frozen=True)
class Augmentation:
    """Effects added to the identified model (all off by default; SI units).

    Attributes
    ----------
    extra_damping
        Modal damping ratio added to the beam's modes [-].
    hunt_crossley
        alpha of the normal force N (1 - alpha deta/dt) [s/m].
    viscous
        sigma_2 of the tangential force S + sigma_2 dxi/dt [N*s/m].
    iwan_share
        Share of the tangential contact carried by a Maxwell-slip (Iwan) element [-].
    mass_error
        Relative error of every transducer mass [-].
    delays
        Each acceleration channel's delay on the force [s], j of them (one per accelerometer; empty: none).
    gains
        Each acceleration channel reads g times its acceleration (a sensitivity error), g [-], j of them (empty:
        none).
    unilateral_exponent
        0 = the linear bilateral spring N0 - k_n eta, p >= 1 = the unilateral power law
        N0 ((delta0 - eta)/delta0)^p with delta0 = p N0 / (c k_n) (the contact may open) [-].
    normal_stiffness_factor
        c, the factor on the linear chain's k_n in the unilateral law (poorly determined by frequencies) [-].
    preload_drift
        Relative change of the preload over the record [-].
    shortening_change
        Relative change of the beam's shortening in the slip [-] (Eq. 9's integral scaled by
        1 + shortening_change; -1: linear kinematics).
    """

    extra_damping: float = 0.0
    hunt_crossley: float = 0.0
    viscous: float = 0.0
    iwan_share: float = 0.0
    mass_error: float = 0.0
    delays: tuple = ()
    gains: tuple = ()
    unilateral_exponent: float = 0.0
    normal_stiffness_factor: float = 1.0
    preload_drift: float = 0.0
    shortening_change: float = 0.0

    def merge(self, other: "Augmentation") -> "Augmentation":
        """Return both augmentations' effects in one.

        Parameters
        ----------
        other
            The augmentation merged over this one: its non-default fields win.

        Returns
        -------
        merged : Augmentation
            This augmentation with ``other``'s non-default fields.
        """
        changes = {
            f.name: getattr(other, f.name) for f in dataclasses.fields(other) if getattr(other, f.name) != f.default
        }
        return dataclasses.replace(self, **changes)


NONE = Augmentation()


@dataclass(frozen=True)
class IdentifiedModel:
    """The chain's identified model, and the chain's stiffness fit for a candidate that redoes it.

    The stiffness fit's fields (``frequencies`` to ``k_n_bounded``) serve a candidate that redoes the fit
    (``structure_with``).

    Attributes
    ----------
    structure
        The structure, with the identified k_t and k_n.
    damping
        Damping ratios of the identified structural modes, by order [-].
    friction
        Friction parameters (e_f [N/m], k_c [1/m], e_t [N/m], kappa [-], mu [-]).
    preload
        Preload N0 [N].
    n_modes
        Number of stuck modes kept.
    oversampling
        The integration's oversampling.
    frequencies
        The identified natural frequencies [Hz].
    regularization
        The reading of Eq. 21 the friction law was fitted with (from friction_fit.nc).
    frequency_sigma
        The frequencies' weights [Hz]; empty: relative residuals.
    stiffness_scale_sd
        The prior sd of ln(E / ``config_modulus``) [-]; 0: E held.
    config_modulus
        The config's Young's modulus [Pa].
    k_n_bounded
        Whether the frequencies bound k_n: the linear modes use the fit's k_n; otherwise they use the prior, and a
        refit holds it.
    test_damping_ratios
        The identified modes' damping ratios in the dual-sine tests [-]; empty: the random test's (``damping``).
    """

    structure: StructureParameters
    damping: tuple
    friction: tuple
    preload: float
    n_modes: int = 8
    oversampling: int = 8
    frequencies: tuple = ()
    regularization: str = "none"
    frequency_sigma: tuple = ()
    stiffness_scale_sd: float = 0.0
    config_modulus: float = 0.0
    k_n_bounded: bool = True
    test_damping_ratios: tuple = ()

    @property
    def test_damping(self) -> tuple:
        """The identified modes' damping ratios in the dual-sine tests [-].

        ``test_damping_ratios`` where given (the model at a factor of ``contactid.test_damping``, weighed by
        ``gap.damping.confirmed_test_damping``), else the random test's (``damping``), as the chain identifies them.

        Returns
        -------
        ratios : tuple
            The damping ratios, by mode [-].
        """
        return tuple(self.test_damping_ratios) or tuple(self.damping)

    def structure_with(self, aug: Augmentation) -> StructureParameters:
        """Return the structure with the augmentation's changes.

        Changed masses re-fit k_t and k_n to the identified natural frequencies, and Young's modulus with them where
        the chain's stiffness fit freed it (the linear chain's stiffness fit redone with the effect in the model,
        ``_refit_contact``); a changed shortening leaves them (a second-order term: the linear chain does not see it).

        Parameters
        ----------
        aug
            The augmentation: its ``shortening_change`` and ``mass_error`` act on the structure.

        Returns
        -------
        structure : StructureParameters
            The changed structure.
        """
        p = self.structure
        if aug.shortening_change:
            p = p.replace(shortening_scale=p.shortening_scale * (1.0 + aug.shortening_change))
        if aug.mass_error:
            m = 1.0 + aug.mass_error
            p = p.replace(
                sensor_masses=tuple(m * x for x in p.sensor_masses), force_transducer_mass=m * p.force_transducer_mass
            )
            p = self.refit_stiffness(p)
        return p

    def refit_stiffness(self, structure: StructureParameters, free_modulus: bool = True) -> StructureParameters:
        """Return a structure with the chain's stiffness fit redone on it (``_refit_contact``).

        k_t and k_n fitted to the identified natural frequencies with the chain's weights, Young's modulus with them
        under the chain's prior where ``free_modulus`` and the chain freed it (otherwise as ``structure`` has it),
        and k_n held where the chain's modes use the prior k_n.

        Parameters
        ----------
        structure
            The structure to refit.
        free_modulus
            Whether Young's modulus may be refitted (where the chain freed it).

        Returns
        -------
        structure : StructureParameters
            The refitted structure; without identified frequencies, ``structure`` as it is.
        """
        if not self.frequencies:
            return structure
        return _refit_contact(
            structure,
            self.frequencies,
            self.frequency_sigma,
            self.stiffness_scale_sd if free_modulus else 0.0,
            self.config_modulus,
            self.k_n_bounded,
        )

    def with_friction(self, friction: Sequence[float]) -> "IdentifiedModel":
        """Return the model with its friction parameters replaced.

        Parameters
        ----------
        friction
            The friction parameters (e_f [N/m], k_c [1/m], e_t [N/m], kappa [-], mu [-]).

        Returns
        -------
        model : IdentifiedModel
            The model with them.
        """
        return dataclasses.replace(self, friction=tuple(float(x) for x in friction))


def identified_model(
    structure_cfg: Mapping,
    linear_modes: xr.Dataset,
    modal: xr.Dataset,
    friction_fit: xr.Dataset,
    n_modes: int = 8,
    oversampling: int = 8,
) -> IdentifiedModel:
    """Return the identified model from the chain's datasets.

    The stiffness fit's prior and weights come from linear_modes.nc's attributes where it has them (otherwise E
    held, relative residuals: the fit of datasets written before they were kept).

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block: reads ``preload_n`` [N] and what ``parameters.identified_structure``
        reads.
    linear_modes
        linear_modes.nc: reads ``k_t``, ``k_n``, ``stiffness_scale`` and the attributes ``frequency_sigma_hz``,
        ``stiffness_scale_sd`` and ``k_n_choice``.
    modal
        modal.nc: reads ``damping_ratio`` and ``natural_frequency`` (mode).
    friction_fit
        friction_fit.nc: reads the law's parameters and the attribute ``regularization``.
    n_modes
        Number of stuck modes kept.
    oversampling
        The integration's oversampling.

    Returns
    -------
    model : IdentifiedModel
        The identified model.
    """
    params = identified_structure(structure_cfg, linear_modes)
    scale = float(linear_modes["stiffness_scale"]) if "stiffness_scale" in linear_modes else 1.0
    attrs = getattr(linear_modes, "attrs", {})
    sigma = tuple(float(s) for s in np.atleast_1d(attrs.get("frequency_sigma_hz", ())))
    return IdentifiedModel(
        params,
        tuple(float(z) for z in modal["damping_ratio"].values),
        tuple(float(x) for x in fitted_parameters(friction_fit)),
        float(structure_cfg["preload_n"]),
        int(n_modes),
        int(oversampling),
        tuple(float(f) for f in modal["natural_frequency"].values),
        str(friction_fit.attrs["regularization"]),
        sigma if len(sigma) == modal.sizes["mode"] else (),
        float(attrs.get("stiffness_scale_sd", 0.0)),
        params.youngs_modulus / scale,
        str(attrs.get("k_n_choice", "best fit")) == "best fit",
    )


# how far above the chain's k_n a mass candidate's refit may take it (decades): see _refit_contact
KN_REFIT_ABOVE = 1.0


@lru_cache(maxsize=64)
def _refit_contact(
    params: StructureParameters,
    frequencies: tuple,
    sigma: tuple = (),
    scale_sd: float = 0.0,
    config_modulus: float = 0.0,
    refit_k_n: bool = True,
) -> StructureParameters:
    """Refit k_t and k_n (and, with ``scale_sd`` > 0, Young's modulus) to the identified natural frequencies.

    The frequencies are in Hz. The stiffness fit of the linear chain (``stiction.stiction_stiffness``), redone from
    the current values (with its Jacobian, ``stiction.JACOBIAN``); k_t within two decades of its value, k_n from two
    decades below to ``KN_REFIT_ABOVE`` decades above.

    Residuals (f - f_id) / ``sigma`` (the chain's weights, Hz; empty: relative residuals f / f_id - 1) and, with
    ``scale_sd`` > 0, the chain's prior ln(E / ``config_modulus``) / ``scale_sd`` on a free E within
    ``stiction.LN_SCALE_BOUNDS`` of the config's. Held at the chain's E, a mass candidate's refit gave the chain's
    stiffness scale (1.0043 on transducer masses 30 % heavy: the scale had taken up part of the mass error) to the
    refitted structure, and the candidate's calibration settled at +62 %; with E refitted as the chain fits it,
    at +30.5 % (docs/measurements.md, "The mass candidate's stiffness refit, the line search's safeguard and the
    records' attribution").

    ``refit_k_n`` False: where the frequencies bound k_n from one side only, the chain's linear modes use the prior
    k_n, not the fit's; so does the refit (the fit is the chain's, k_n then set to the prior: at no mass change the
    chain's structure). Returning the fit's k_n moved it to the cap, ten times the prior, at any mass change (+0.8 %
    on a compound benchmark item): the candidate then stood for a normal contact ten times stiffer, and explained
    61 % of what a preload drift left of a multi-asperity friction's gap.

    Above, the frequencies hardly feel k_n (the contact is rigid for them): refitted up to two decades above, k_n ran
    to that bound, 100 times the chain's value, at a transducer-mass error of 10 % or more, for a misfit smaller by
    a few 1e-4 (the frequency floor is 1e-3), and the reduced model got a normal mode at 34-36 kHz instead of 3.8 kHz,
    which the integrator then resolved with 3.5 times the steps (``simulator``). Capped, the misfit is within 2e-4 of
    that and the mode at most sqrt(10) times the chain's (11 kHz: 9 steps per sample instead of 8).
    """
    from scipy.optimize import least_squares

    from ..beam_modes import ContactFrequencyMap
    from ..stiction import JACOBIAN, LN_SCALE_BOUNDS

    f_id = np.asarray(frequencies)
    fmap = ContactFrequencyMap(params, len(f_id))
    x0 = np.log10([params.k_t, params.k_n])
    lo, hi = x0 - 2, x0 + [2, KN_REFIT_ABOVE]
    weights = np.asarray(sigma, dtype=float) if len(sigma) == len(f_id) else f_id

    def contact(x):
        return float(10.0 ** x[0]), float(10.0 ** x[1])

    def result(x):  # k_n held where the chain's modes use the prior: the fit's k_n (flat there) is not used
        return float(10.0 ** x[0]), (float(10.0 ** x[1]) if refit_k_n else params.k_n)

    if scale_sd > 0 and config_modulus > 0:
        ln_s0 = float(np.log(params.youngs_modulus / config_modulus))  # the current E over the config's

        def residuals(x):
            r = (fmap(*contact(x), float(np.exp(x[2]))) - f_id) / weights
            return np.append(r, (ln_s0 + x[2]) / scale_sd)

        res = least_squares(
            residuals,
            [*x0, 0.0],
            bounds=([*lo, LN_SCALE_BOUNDS[0] - ln_s0], [*hi, LN_SCALE_BOUNDS[1] - ln_s0]),
            x_scale=[0.1, 0.1, 0.01],
            xtol=1e-10,
            ftol=1e-12,
            **JACOBIAN,
        )
        p = params.with_contact(*result(res.x))
        return p.replace(youngs_modulus=params.youngs_modulus * float(np.exp(res.x[2])))
    res = least_squares(
        lambda x: (fmap(*contact(x)) - f_id) / weights,
        x0,
        bounds=(lo, hi),
        x_scale=0.1,
        xtol=1e-10,
        ftol=1e-12,
        **JACOBIAN,
    )
    return params.with_contact(*result(res.x))


@lru_cache(maxsize=32)
def reduced(params: StructureParameters, n_modes: int) -> tuple[FEModel, ReducedModel]:
    """Return the FE model of a structure and its reduced model on the lowest stuck modes.

    The reduced model is ``rig.nonlinear.reduced_model``'s; the last 32 pairs are cached.

    Parameters
    ----------
    params
        The structure.
    n_modes
        Number of stuck modes the reduced model keeps.

    Returns
    -------
    model : FEModel
        The FE model.
    reduced : ReducedModel
        Its reduced model.
    """
    model = assemble(params)
    return model, reduced_model(model, n_modes)


def fe_model(model: IdentifiedModel, aug: Augmentation = NONE) -> FEModel:
    """Return the identified model's FE model, with the augmentation's structural changes.

    Parameters
    ----------
    model
        The identified model.
    aug
        The augmentation (``IdentifiedModel.structure_with``).

    Returns
    -------
    fe : FEModel
        The FE model.
    """
    return reduced(model.structure_with(aug), model.n_modes)[0]
