"""Model updating of the base (linear) structure from the random test, before contact effects are tried.

The identified model assumes the configured ``structure``; a real rig is a few per cent off everywhere.
The random test's modal fit gives the natural frequencies f_i (with their standard errors) and the
magnitudes of the accelerance residues |R_si| = |phi_i(x_s) phi_i(x_d)| / (2 omega_i) (mass-normalised
shapes at the sensors and the drive point), which carry the mode shapes and the mass scaling, not the
frequencies alone. Updating fits the stuck contact's k_t, k_n and scale factors of the structure to both,
as a maximum a posteriori estimate: each structural factor x_j = ln(theta_j / theta_j,nominal) has a
Gaussian prior N(0, s_j^2) (its plausible spread about the nominal value), so parameters the data do not
bound stay at their nominal values instead of wandering along a valley. The clamp's factor scales its rotational
compliance 1/k_c, a rigid clamp taken as CLAMP_RIGID once it moves; as a rigid clamp gives the fit no gradient, the fit
is started again from each factor's further ``starts`` and keeps the lower posterior misfit. The force transducer's
mass has a factor of its own beyond the common one of every transducer (a rig's transducers are off apart).

Identifiability is stated per parameter from the linearised posterior: the posterior standard deviation
over the prior's (``posterior_over_prior``); a ratio below IDENTIFIED (0.5) means the data bound the
parameter, otherwise it is set by its prior. Each factor's profile (the posterior misfit's rise when it is held at
its nominal value) says whether it moved; the factors of a PROFILE_GROUPS group (the two transducer-mass factors, each
partly taken up by the other) are also held at nominal together. The strongest posterior correlation names the
parameter it trades off against (for example k_t against the tangential lever arm: the frequencies see about
a^2 k_t k_b / (k_t + k_b)).

The update is accepted when it lowers the data misfit chi^2 by more than the drop the nominal structure would give
with probability 1 - confidence (0.95 by default): chi^2_k(confidence) for k factors the data bind, less where the
data leave a factor at its prior (the drop's null distribution from the hat matrices of the prior-weighted fits,
``null_drop_weights``; a rigid clamp's compliance, a lever arm the data do not see add nothing to it). Otherwise the
nominal structure is kept and the update is offered as ``proposal``: the gap diagnosis may still accept it when it
shrinks the held-out gap of the dual-sine records materially (``UpdatingResult.accept_proposal``,
``gap.base_model.updated_model``): with the frequency floor the random test alone cannot make transducer masses 7-22 %
off significant, yet the update finds them (docs/gap.md, "Model updating").
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Mapping, NamedTuple, Sequence

import numpy as np

from .finite_differences import central_difference_jacobian
from .parameters import StructureParameters
from .updating_model import DEFAULT_FACTORS, FACTORS, PROFILE_GROUPS, apply_factors, modal_predictions
from .updating_result import UpdatingResult

if TYPE_CHECKING:
    from scipy.optimize import OptimizeResult

IDENTIFIED = 0.5  # posterior sd / prior sd below this: the data bound the parameter
DIFF_STEP = 1e-5  # finite-difference step of the MAP fit's Jacobian, absolute, on the logs of the parameters


def _prior_sds(names: list, contact_prior_sd: float, prior_sd) -> np.ndarray:
    """Return the prior sd of (ln k_t, ln k_n, ln factor for each of ``names``).

    ``contact_prior_sd`` for the contact, FACTORS' spreads for the factors unless ``prior_sd`` ({factor: sd}) replaces
    them; an unknown factor is refused.
    """
    for f in names:
        if f not in FACTORS:
            raise ValueError(f"gap.model_updating.parameters: unknown {f!r}; choose from {', '.join(FACTORS)}")
    priors = {f: FACTORS[f].prior_sd for f in names} | {k: float(v) for k, v in dict(prior_sd or {}).items()}
    return np.array([contact_prior_sd, contact_prior_sd] + [priors[f] for f in names])


def gain_basis(j: int) -> np.ndarray:
    """Return an orthonormal basis of the plane where j channels' log gains sum to zero.

    The plane holds the channels relative to one another. A gain common to every channel scales all residues as the
    transducer masses nearly do (exact modal data of masses 30 % heavy: free common gains took the update's drop below
    significance), so it is left out.

    Parameters
    ----------
    j
        Number of channels (accelerometers).

    Returns
    -------
    basis : np.ndarray
        Orthonormal columns, each summing to zero [-], shape (j, j - 1).
    """
    return np.linalg.qr(np.vstack([np.ones(j), np.eye(j)[: j - 1]]).T)[0][:, 1:]


class _UpdatingProblem:
    """Misfit of the structure x to the modal data.

    x = (ln k_t, ln k_n, ln factors, ln channel gains); the misfit is of the frequencies (Hz) over their standard errors
    and, unless ``R_id`` is None, of the residues over ``residue_accuracy`` of their value. ``n_gains`` (0, or the
    sensors' number less one): the accelerometer channels' sensitivity factors on their residues relative to one another
    (the measurement chain's, not the structure's), as coordinates of their logs in the plane where those sum to zero
    (``gain_basis``).

    Parameters
    ----------
    params
        The nominal structure (its k_t, k_n replaced by exp(x[0]), exp(x[1])).
    names
        The structural factors in x, in order (keys of ``updating_model.FACTORS``).
    f_id
        Identified natural frequencies [Hz], shape (n_modes,).
    f_sd
        Their standard errors [Hz], shape (n_modes,).
    R_id
        Identified residue magnitudes |R_si| [s/kg], shape (n_sensors, n_modes); None: frequencies alone.
    residue_accuracy
        Relative standard error of a residue [-].
    sd
        The prior sds of x [-], shape (2 + n_factors + n_gains,).
    n_gains
        Number of gain coordinates at the end of x: 0, or the sensors' number less one.
    """

    def __init__(
        self,
        params: StructureParameters,
        names: Sequence[str],
        f_id: np.ndarray,
        f_sd: np.ndarray,
        R_id: np.ndarray | None,
        residue_accuracy: float,
        sd: np.ndarray,
        n_gains: int = 0,
    ):
        self.params, self.names, self.sd = params, names, sd
        self.f_id, self.f_sd, self.R_id, self.residue_accuracy = f_id, f_sd, R_id, residue_accuracy
        self.n = f_id.size
        self.n_gains = int(n_gains)

    def structure(self, x: np.ndarray) -> StructureParameters:
        """Return the structure at x.

        Parameters
        ----------
        x
            The parameters, x = (ln k_t, ln k_n, ln factors, the gains' log coordinates), k_t and k_n in [N/m], the
            others [-], shape (2 + n_factors + n_gains,).

        Returns
        -------
        structure : StructureParameters
            The nominal structure with k_t, k_n and the factors applied.
        """
        return apply_factors(
            self.params.with_contact(float(np.exp(x[0])), float(np.exp(x[1]))),
            {f: float(np.exp(v)) for f, v in zip(self.names, x[2:])},
        )

    def data_residuals(self, x: np.ndarray) -> np.ndarray:
        """Return the scaled residuals of the frequencies, then of the residues (sensor by sensor).

        Each is 1e3 where the structure has no modes to compare.

        Parameters
        ----------
        x
            The parameters, x = (ln k_t, ln k_n, ln factors, the gains' log coordinates), k_t and k_n in [N/m], the
            others [-], shape (2 + n_factors + n_gains,).

        Returns
        -------
        residuals : np.ndarray
            Frequency residuals over their standard errors, then residue residuals over ``residue_accuracy`` of their
            value [-], shape (n_modes,) or (n_modes + n_sensors n_modes,).
        """
        n, R_id = self.n, self.R_id
        try:
            f, R = modal_predictions(self.structure(x), n)
        except ValueError:
            return np.full(n + (0 if R_id is None else R_id.size), 1e3)
        r = [(f - self.f_id) / self.f_sd]
        if R_id is not None:
            if self.n_gains:
                R = R * np.exp(gain_basis(R.shape[0]) @ np.asarray(x[-self.n_gains :], float))[:, None]
            r.append(((R - R_id) / (self.residue_accuracy * R_id)).ravel())
        return np.concatenate(r)

    def fit(
        self, x_centre: np.ndarray, free: np.ndarray, start: np.ndarray | None = None
    ) -> tuple[np.ndarray, OptimizeResult]:
        """Return the maximum a posteriori fit of the ``free`` entries of x, the others held at ``x_centre``.

        ``x_centre`` is the centre of the prior and the start (or ``start``'s free entries). The Jacobian is taken by
        central differences with absolute steps ``DIFF_STEP`` of the logs.

        Parameters
        ----------
        x_centre
            Centre of the prior and the values of the fixed entries, x = (ln k_t, ln k_n, ln factors, the gains' log
            coordinates), k_t and k_n in [N/m], the others [-], shape (n_x,).
        free
            Which entries of x are fitted, shape (n_x,), boolean.
        start
            Start of the fit, shape (n_x,) (its free entries are used); None: ``x_centre``.

        Returns
        -------
        x : np.ndarray
            The fitted parameters, x = (ln k_t, ln k_n, ln factors, the gains' log coordinates), k_t and k_n in [N/m],
            the others [-], shape (n_x,).
        result : OptimizeResult
            scipy's least-squares result (residuals: the data's, then the prior's of the free entries).
        """
        sd = self.sd

        def res(z):
            x = x_centre.copy()
            x[free] = z
            return np.concatenate([self.data_residuals(x), ((x - x_centre) / sd)[free]])

        z0 = (x_centre if start is None else np.asarray(start, float))[free]
        # central differences with absolute steps of 1e-5 of the logs: the default forward steps (1.5e-8) resolve the
        # flat directions (the lever arm against k_t, a stiff k_n) no better than the eigensolver's rounding, so the
        # fit stopped wherever the noisy Jacobian sent it, a posterior misfit several times the optimum's, and a
        # change of 1e-8 in the frequencies moved the factors by per cents. scipy's diff_step is relative to x,
        # a step of 1e-5 |ln factor|, 1e-11 at a factor of 1.000001: the posterior sd of a lever arm the data do not
        # bind came out 0.0002-0.1 (docs/measurements.md, "The updating's Jacobian")
        from scipy.optimize import least_squares  # here: the contact-force jobs import this module for its results

        sol = least_squares(
            res,
            z0,
            jac=central_difference_jacobian(res, DIFF_STEP),
            x_scale=sd[free] * 0.1,
            xtol=1e-10,
            ftol=1e-12,
            max_nfev=400,
        )
        x = x_centre.copy()
        x[free] = sol.x
        return x, sol


def null_drop_weights(data_jacobian: np.ndarray, sd: np.ndarray, n_contact: int = 2, n_nuisance: int = 0) -> np.ndarray:
    """Return the weights lambda_i of the update's chi^2 drop under the nominal structure.

    The drop ~ sum_i lambda_i chi^2_1. The first ``n_contact`` entries of x, and the last ``n_nuisance`` (the channel
    gains), are fitted in the nominal fit too. Linearised, a fit with the Gaussian prior P = diag(1 / sd^2) leaves the
    residual (I - H) e with the hat matrix H = J (J^T J + P)^-1 J^T, so the drop from the nominal fit (H0, the contact
    columns) to the update (H1) is e^T [(I - H0)^2 - (I - H1)^2] e, whose null distribution is sum_i lambda_i chi^2_1
    over that matrix's eigenvalues. A factor the data bind adds a weight near 1 (k bound factors: chi^2_k), one the data
    leave at its prior a weight near 0 (posterior sd / prior sd r: 1 - r^4 for a factor uncorrelated with the others).

    Parameters
    ----------
    data_jacobian
        Jacobian of the scaled data residuals (unit variance) in x = (ln k_t, ln k_n, ln factors) [-],
        shape (n_data, p).
    sd
        Prior sds of x [-], shape (p,).
    n_contact
        Number of leading entries of x (the contact's) fitted in the nominal fit.
    n_nuisance
        Number of trailing entries of x (the channel gains) fitted in the nominal fit.

    Returns
    -------
    weights : np.ndarray
        The eigenvalues lambda_i, clipped at zero [-], shape (n_data,).
    """
    J = np.asarray(data_jacobian, float)
    P = np.diag(1.0 / np.asarray(sd, float) ** 2)
    eye = np.eye(J.shape[0])

    def rest(cols):  # I - H over the columns cols
        Jc = J[:, cols]
        return eye - Jc @ np.linalg.solve(Jc.T @ Jc + P[np.ix_(cols, cols)], Jc.T)

    p = J.shape[1]
    R0, R1 = rest(list(range(n_contact)) + list(range(p - n_nuisance, p))), rest(list(range(p)))
    A = R0 @ R0 - R1 @ R1
    return np.clip(np.linalg.eigvalsh(0.5 * (A + A.T)), 0.0, None)


def chi2_drop_threshold(weights: np.ndarray | Sequence[float], confidence: float) -> float:
    """Return the drop of chi^2 that sum_i w_i chi^2_1 (``null_drop_weights``) exceeds with probability 1 - confidence.

    By Satterthwaite's match of mean and variance, c chi^2_nu with c = sum w^2 / sum w, nu = (sum w)^2 / sum w^2 (exact
    where every weight is 0 or 1: k weights of 1 give chi^2_k(confidence)); inf where no weight is left (the data bind
    no factor, and no drop is significant).

    Parameters
    ----------
    weights
        The null distribution's weights (``null_drop_weights``) [-], shape (n_data,).
    confidence
        The test's confidence level [-].

    Returns
    -------
    threshold : float
        The drop of chi^2 [-]; inf where the weights sum to (nearly) zero.
    """
    from scipy.stats import chi2  # here: scipy.stats takes 0.3 s to import

    w = np.asarray(weights, float)
    s1, s2 = float(w.sum()), float((w**2).sum())
    if s1 <= 1e-9:
        return math.inf
    return float(s2 / s1 * chi2.ppf(confidence, s1 * s1 / s2))


def _posterior_identifiability(jacobian, sd, labels: list) -> tuple[np.ndarray, dict]:
    """Return the linearised posterior's covariance of x and each parameter's identifiability.

    (covariance of x from the Jacobian of the residuals (data + prior) at the optimum, the linearised posterior; {label:
    posterior sd, prior sd, their ratio, whether the data bound it (ratio < IDENTIFIED), the parameter it correlates
    with most and the correlation}).
    """
    J = jacobian
    try:
        cov = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(J.T @ J)
    post_sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    corr = cov / np.outer(post_sd, post_sd)
    ident = {}
    for i, name in enumerate(labels):
        others = [j for j in range(len(labels)) if j != i]
        j = max(others, key=lambda j: abs(corr[i, j])) if others else None
        ratio = float(post_sd[i] / sd[i])
        ident[name] = {
            "posterior_sd": float(post_sd[i]),
            "prior_sd": float(sd[i]),
            "posterior_over_prior": ratio,
            "bound_by_data": bool(ratio < IDENTIFIED),
            "most_correlated_with": labels[j] if j is not None else None,
            "correlation": float(corr[i, j]) if j is not None else None,
        }
    return cov, ident


class ChannelGainTest(NamedTuple):
    """Answer of ``channel_gains_significant``, with the two nominal fits that ``update_structure`` starts from.

    Attributes
    ----------
    significant
        Whether the gains lower the nominal fit's chi^2 by more than chi^2_(j-1)(confidence).
    gains
        Each channel's gain relative to the others (their logs sum to zero) [-], one per accelerometer.
    sd
        Posterior sd of each gain's ln [-], one per accelerometer.
    x_with
        The nominal fit with the gains: x = (ln k_t, ln k_n, the factors at nominal (0), the gains' log coordinates),
        k_t and k_n in [N/m], shape (2 + n_factors + n_sensors - 1,).
    x_without
        The nominal fit without them: x = (ln k_t, ln k_n, the factors at nominal (0)), k_t and k_n in [N/m],
        shape (2 + n_factors,).
    """

    significant: bool
    gains: tuple
    sd: tuple
    x_with: np.ndarray
    x_without: np.ndarray


def channel_gains_significant(
    params: StructureParameters,
    names: Sequence[str],
    f_id: np.ndarray,
    f_sd: np.ndarray,
    R_id: np.ndarray,
    residue_accuracy: float,
    sd: np.ndarray,
    gain_sd: float,
    confidence: float,
) -> ChannelGainTest:
    """Return whether the channels' relative gains are significant, with their fit.

    The channels' gains relative to one another (``gain_basis``, prior sd ``gain_sd`` of their logs) are fitted with k_t
    and k_n on the nominal structure, with the posterior sd of each one's log; they are significant where they lower its
    chi^2 by more than chi^2_(j-1)(confidence): the residues call the channels miscalibrated. Where they do not, the
    update is made without them: fitted always, they took part of a structure's own misfit at the sensors (the compound
    benchmark's update of compound-14-s1 went from 16.2 % to 13.6 % instead of 15.0 %, and its normal dashpot was no
    longer named).

    Parameters
    ----------
    params
        The nominal structure, with the chain's k_t, k_n as the start.
    names
        The structural factors of the update (held at nominal here).
    f_id
        Identified natural frequencies [Hz], shape (n_modes,).
    f_sd
        Their standard errors [Hz], shape (n_modes,).
    R_id
        Identified residue magnitudes |R_si| [s/kg], shape (n_sensors, n_modes).
    residue_accuracy
        Relative standard error of a residue [-].
    sd
        Prior sds of (ln k_t, ln k_n, ln factors) [-], shape (2 + n_factors,).
    gain_sd
        Prior sd of the ln of a channel's relative gain [-].
    confidence
        The test's confidence level [-].

    Returns
    -------
    test : ChannelGainTest
        Whether the gains are significant, the gains, their sds and the two nominal fits.
    """
    from scipy.stats import chi2  # here: scipy.stats takes 0.3 s to import

    j = R_id.shape[0]
    x = np.array([np.log(params.k_t), np.log(params.k_n)] + [0.0] * (len(names) + j - 1))
    sd_g = np.concatenate([sd, np.full(j - 1, float(gain_sd))])
    with_gains = _UpdatingProblem(params, names, f_id, f_sd, R_id, residue_accuracy, sd_g, j - 1)
    without = _UpdatingProblem(params, names, f_id, f_sd, R_id, residue_accuracy, sd, 0)
    free = np.array([True, True] + [False] * len(names) + [True] * (j - 1))
    x_g, sol = with_gains.fit(x, free)
    x_0, _ = without.fit(x[: 2 + len(names)], free[: 2 + len(names)])
    drop = float(np.sum(without.data_residuals(x_0) ** 2) - np.sum(with_gains.data_residuals(x_g) ** 2))
    B = gain_basis(j)
    J = sol.jac  # of (data, prior) residuals in the free entries: k_t, k_n, the gains
    try:
        cov = np.linalg.inv(J.T @ J)[2:, 2:]
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(J.T @ J)[2:, 2:]
    gains = tuple(float(v) for v in np.exp(B @ x_g[len(x_g) - (j - 1) :]))
    gain_sd_post = tuple(float(v) for v in np.sqrt(np.diag(B @ cov @ B.T)))
    return ChannelGainTest(drop > float(chi2.ppf(confidence, j - 1)), gains, gain_sd_post, x_g, x_0)


def update_structure(
    params: StructureParameters,
    f_id_hz: np.ndarray | Sequence[float],
    f_sigma_hz: np.ndarray | Sequence[float],
    residues: np.ndarray | None,
    residue_accuracy: float = 0.01,
    factors: Sequence[str] = DEFAULT_FACTORS,
    contact_prior_sd: float = 3.0,
    confidence: float = 0.95,
    prior_sd: Mapping[str, float] | None = None,
    gain_sd: float = 0.0,
) -> UpdatingResult:
    """Update the structure ``params`` (with its k_t, k_n as the start) to the random test's modal data.

    The update is accepted when chi^2 drops by more than ``chi2_drop_threshold`` (chi^2_k(confidence) for k factors the
    data bind). The accelerometer channels' relative gains (``gain_sd`` > 0), where they lower the nominal fit's chi^2
    significantly (``channel_gains_significant``), are fitted with k_t and k_n in the nominal fit and in the update
    alike (the measurement chain's, not counted among the factors the update adds; ``UpdatingResult.channel_gains``): a
    channel 2 % off otherwise made the random test's residues call for a clamp compliance 900 times the nominal's. See
    the module's docstring.

    Parameters
    ----------
    params
        The nominal structure, with the chain's k_t, k_n as the start.
    f_id_hz
        Identified natural frequencies [Hz], shape (n_modes,).
    f_sigma_hz
        Their standard errors [Hz], shape (n_modes,).
    residues
        The modal fit's residue magnitudes |R_si| [s/kg], shape (n_sensors, n_modes); None: frequencies alone.
    residue_accuracy
        Relative standard error of a residue [-].
    factors
        Names of FACTORS to update.
    contact_prior_sd
        Prior sd of ln k_t and ln k_n (wide) [-].
    confidence
        Confidence level of the acceptance test [-].
    prior_sd
        {factor: sd of its ln} [-] replacing FACTORS' prior spreads (a lever arm measured to 1 %: 0.01); None: FACTORS'.
    gain_sd
        Prior sd of the ln of the accelerometer channels' sensitivity factors relative to one another (their logs
        summing to zero, ``gain_basis``) on the residues [-]; 0: none.

    Returns
    -------
    result : UpdatingResult
        The update: factors, k_t, k_n, structure, chi^2 before and after, acceptance or proposal, identifiability with
        each factor's profile, channel gains and, where the gains took part, the same update without them.
    """
    f_id = np.asarray(f_id_hz, float)
    f_sd = np.asarray(f_sigma_hz, float)
    n = f_id.size
    R_id = None if residues is None else np.asarray(residues, float)
    names = [str(f) for f in factors]
    sd = _prior_sds(names, contact_prior_sd, prior_sd)
    n_gains = R_id.shape[0] - 1 if R_id is not None and gain_sd > 0 and R_id.shape[0] > 1 else 0
    gain_test = None
    if n_gains:
        gain_test = channel_gains_significant(
            params, names, f_id, f_sd, R_id, residue_accuracy, sd, gain_sd, confidence
        )
        if not gain_test.significant:
            n_gains = 0  # channels the residues do not call miscalibrated: the update as without the gains
    sd = np.concatenate([sd, np.full(n_gains, float(gain_sd))])
    x_nom = np.array([np.log(params.k_t), np.log(params.k_n)] + [0.0] * (len(names) + n_gains))
    problem = _UpdatingProblem(params, names, f_id, f_sd, R_id, residue_accuracy, sd, n_gains)
    contact_only = np.array([True, True] + [False] * len(names) + [True] * n_gains)
    if gain_test is None:
        x0, _ = problem.fit(x_nom, contact_only)  # the nominal structure with k_t, k_n refitted to the same data
    else:  # the same fit, made by the gains' test
        x0 = gain_test.x_with if gain_test.significant else gain_test.x_without
    chi2_nominal = float(np.sum(problem.data_residuals(x0) ** 2))
    free = np.ones(x_nom.size, bool)
    x_start = x_nom.copy()
    x_start[:2] = x0[:2]  # the contact parameters start (and their wide prior is centred) at the refitted k_t, k_n
    x1, sol = problem.fit(x_start, free)
    for i, name in enumerate(names):  # the further starts of factors with no gradient at their nominal value
        factor = FACTORS[name]
        for start in factor.starts if factor.needs_starts is None or factor.needs_starts(params) else ():
            x_alt = x1.copy()
            x_alt[2 + i] = np.log(start)
            x2, sol2 = problem.fit(x_start, free, start=x_alt)
            if sol2.cost < sol.cost:
                x1, sol = x2, sol2
    data_residuals = problem.data_residuals(x1)
    chi2_updated = float(np.sum(data_residuals**2))
    weights = null_drop_weights(sol.jac[: data_residuals.size], sd, n_nuisance=n_gains)
    threshold = chi2_drop_threshold(weights, confidence)
    accepted = bool(names) and bool(chi2_nominal - chi2_updated > threshold)
    cov, ident = _posterior_identifiability(sol.jac, sd, ["k_t", "k_n"] + names + [f"gain_{k}" for k in range(n_gains)])
    # the channel gains' posterior (marginalised out of the structure's: its covariance is the block without them)
    for k in range(n_gains):
        ident.pop(f"gain_{k}")
    gain_cov = cov[2 + len(names) :, 2 + len(names) :]
    cov = cov[: 2 + len(names), : 2 + len(names)]

    # each factor's profile: the posterior misfit's rise when it is held at its nominal value (also for an update
    # not accepted here: the records may accept it, and the verdict reads the profiles)
    def profile(idx) -> float:  # the posterior misfit's rise with the factors idx held at nominal
        hold = free.copy()
        hold[[2 + i for i in idx]] = False
        _, sol_h = problem.fit(x_start, hold, start=x1)  # from the update: the others are near their optimum
        return float(max(2.0 * (sol_h.cost - sol.cost), 0.0))

    for i, name in enumerate(names):
        ident[name]["profile_chi2_increase"] = profile([i])
    # factors that together make one quantity (the transducer masses: all of them, and the force transducer's
    # beyond): held at nominal together, as each alone is partly taken up by the other
    for group, members in PROFILE_GROUPS.items():
        idx = [i for i, name in enumerate(names) if name in members]
        if len(idx) > 1:
            rise = profile(idx)
            for i in idx:
                ident[names[i]].update(group=group, group_profile_chi2_increase=rise)
    x = x1 if accepted else x0
    f_best, _ = modal_predictions(problem.structure(x), n)
    structure_alone = None
    if n_gains:
        # the same update without the gains: a clamp that gives, say, shapes the residues at the sensors as channel
        # gains nearly do, and the gains' prior is the cheaper (a rig with a 2e5 N m/rad clamp, E -3 %, transducers
        # +40 %: gains of 0.6-0.9 % took the clamp's place, chi^2 1.08 against 1.14 without them, and its dashpot
        # was refitted at 673 s/m for 300). Where the drop the gains add is not significant, the records decide
        from scipy.stats import chi2 as _chi2

        alone = update_structure(
            params, f_id_hz, f_sigma_hz, residues, residue_accuracy, factors, contact_prior_sd, confidence, prior_sd
        )
        drop = float(alone.chi2_updated - chi2_updated)
        bar = float(_chi2.ppf(confidence, n_gains))
        structure_alone = {
            **alone.summary(),
            "gains_drop": drop,
            "gains_threshold": bar,
            "gains_needed": bool(drop > bar),
            "nominal_channel_gains": list(gain_test.gains),
            "nominal_channel_gain_sd": list(gain_test.sd),
        }
    return UpdatingResult(
        {f: float(np.exp(v)) for f, v in zip(names, x[2:])},
        float(np.exp(x[0])),
        float(np.exp(x[1])),
        problem.structure(x),
        chi2_nominal,
        chi2_updated,
        accepted,
        ident,
        f_best,
        int(n + (0 if R_id is None else R_id.size)),
        cov.tolist(),
        params,
        None
        if accepted or not names
        else {
            "factors": {f: float(np.exp(v)) for f, v in zip(names, x1[2:])},
            "k_t": float(np.exp(x1[0])),
            "k_n": float(np.exp(x1[1])),
        },
        "random_test" if accepted else "",
        chi2_threshold=threshold,
        effective_factors=float(np.sum(weights)),
        channel_gains=tuple(float(v) for v in np.exp(gain_basis(n_gains + 1) @ x[len(x) - n_gains :]))
        if n_gains
        else (gain_test.gains if gain_test is not None else ()),
        channel_gain_sd=tuple(
            float(v) for v in np.sqrt(np.diag(gain_basis(n_gains + 1) @ gain_cov @ gain_basis(n_gains + 1).T))
        )
        if n_gains
        else (gain_test.sd if gain_test is not None else ()),
        channel_gains_significant=gain_test is not None and gain_test.significant,
        structure_alone=structure_alone,
    )
