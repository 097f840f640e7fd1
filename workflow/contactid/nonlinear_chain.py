"""The nonlinear chain's datasets, one per step and load case (Sections 4-5).

Generalized coordinates -> nonlinear modes -> reduced model (the paper's S, N) -> contact forces (both methods side by
side, scored against the rig truth where it exists).
"""

from __future__ import annotations

from typing import Iterable, Mapping, Sequence

import numpy as np
import xarray as xr

from .beam_model import FEModel, assemble
from .beam_modes import structural_modes
from .harmonics import fourier_series, synthesize
from .identification import (
    galerkin_contact_forces,
    generalized_coordinates,
    inverse_harmonics,
    inverse_identification,
    nnm_coordinates,
    nonlinear_mode_coefficients,
    nrmse,
)
from .modal_damping import modal_damping_vector
from .parameters import StructureParameters, identified_structure
from .raw_checks_dual_sine import driving_point_index


def linear_model(structure_cfg: Mapping, linear_modes: xr.Dataset) -> FEModel:
    """Return the identified linear FE model (the stiffnesses the linear chain chose).

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` block.
    linear_modes
        The linear chain's modes (results/linear/linear_modes.nc): its ``k_t``, ``k_n`` [N/m] and, where
        present, ``stiffness_scale`` are read.

    Returns
    -------
    model : FEModel
        The structure of ``structure_cfg`` with those stiffnesses, assembled.
    """
    return assemble(identified_structure(structure_cfg, linear_modes))


def _record(raw: xr.Dataset):
    return (
        raw["force"].values,
        raw["acceleration"].values,
        float(raw.attrs["sampling_rate_hz"]),
        float(raw.attrs["excitation_frequency_hz"]),
    )


def generalized_coordinates_dataset(raw: xr.Dataset, linear_modes: xr.Dataset, n_harmonics: int) -> xr.Dataset:
    """Return the generalized coordinates' dataset (Eqs. 15-17).

    p''(t) from the sensors, its K-harmonic Fourier series and p(t) by analytic integration.

    Parameters
    ----------
    raw
        The load case's dual-sine record (``io.read_raw``): ``force`` [N] and ``acceleration`` [m/s^2] over
        ``time`` [s], the attributes ``sampling_rate_hz`` and ``excitation_frequency_hz``.
    linear_modes
        The linear chain's modes (results/linear/linear_modes.nc): its ``phi_sensor`` (the mass-normalised shapes at
        the sensors) and ``mode`` are read.
    n_harmonics
        Harmonics K of the excitation frequency in the Fourier series.

    Returns
    -------
    gc : xr.Dataset
        ``p_ddot_measured``, ``p_ddot`` [kg^0.5 m/s^2] and ``p`` [kg^0.5 m] over (``mode``, ``time``), the harmonics'
        ``amplitude`` [kg^0.5 m/s^2] and ``phase`` [rad] over (``mode``, ``harmonic``).
    """
    force, acc, fs, f0 = _record(raw)
    phi_s = linear_modes["phi_sensor"].values
    pdd, coef = generalized_coordinates(phi_s, acc, fs, f0, n_harmonics)
    t = raw["time"].values
    return xr.Dataset(
        {
            "p_ddot_measured": (
                ("mode", "time"),
                pdd,
                {"units": "kg^0.5 m/s^2", "long_name": "p''(t) = Phi^+ w''(t) (Eq. 15)"},
            ),
            "p_ddot": (
                ("mode", "time"),
                synthesize(coef, f0, t, 0),
                {"units": "kg^0.5 m/s^2", "long_name": "Fourier series of p'' (Eq. 16)"},
            ),
            "p": (
                ("mode", "time"),
                synthesize(coef, f0, t, -2),
                {"units": "kg^0.5 m", "long_name": "p(t) by analytic integration (Eq. 17)"},
            ),
            "amplitude": (("mode", "harmonic"), np.abs(coef), {"units": "kg^0.5 m/s^2", "long_name": "A_ki of Eq. 16"}),
            "phase": (
                ("mode", "harmonic"),
                np.angle(coef),
                {"units": "rad", "long_name": "psi_ki of Eq. 16 (sine reference)"},
            ),
        },
        coords={
            "mode": linear_modes["mode"].values,
            "time": ("time", t, {"units": "s"}),
            "harmonic": np.arange(1, n_harmonics + 1),
        },
        attrs={"excitation_frequency_hz": f0, "n_harmonics": n_harmonics},
    )


def nonlinear_modes_dataset(
    gc: xr.Dataset,
    linear_modes: xr.Dataset,
    raw: xr.Dataset,
    structure_cfg: Mapping,
    n_harmonics: int,
    phase_limit_deg: float,
) -> xr.Dataset:
    """Return the nonlinear modes' dataset: Eq. 20's two real NNMs, the phase check and the NNM coordinates.

    With the reconstruction of the driving-point acceleration from the NNMs (Fig. 5) and its NRMSE.

    Parameters
    ----------
    gc
        The generalized coordinates' dataset (``generalized_coordinates_dataset``): its ``amplitude`` and ``phase``
        are read.
    linear_modes
        The linear chain's modes (results/linear/linear_modes.nc): ``phi_sensor``, ``phi``, ``u``, ``y_s``,
        ``theta_s``, ``mode`` and ``x`` are read.
    raw
        The load case's dual-sine record (``io.read_raw``): ``force`` [N] and ``acceleration`` [m/s^2] over
        ``time`` [s], the attributes ``sampling_rate_hz`` and ``excitation_frequency_hz``.
    structure_cfg
        The config's ``structure`` block; its ``excitation_position_m`` [m] (the driving point) is read.
    n_harmonics
        Harmonics K of the excitation frequency kept in the NNM coordinates.
    phase_limit_deg
        Largest phase spread of a real NNM's terms (nonlinear.phase_limit_deg); beyond it the attribute
        ``complex_modes`` is 1 [deg].

    Returns
    -------
    nnm : xr.Dataset
        The NNMs' coefficients on the linear modes, their phase spread, shapes and coordinates ``q``, ``q_ddot``
        over (``nnm``, ``time``), the measured and reconstructed driving-point accelerations [m/s^2].
    """
    force, acc, fs, f0 = _record(raw)
    coef_c = gc["amplitude"].values * np.exp(1j * gc["phase"].values)
    coef, spread = nonlinear_mode_coefficients(coef_c)
    psi_s = linear_modes["phi_sensor"].values @ coef.T
    q, qdd = nnm_coordinates(psi_s, acc, fs, f0, n_harmonics)
    i = driving_point_index(raw, float(structure_cfg["excitation_position_m"]), "raw record")
    recon = (psi_s @ qdd)[i]
    measured = acc[i]
    lm = linear_modes
    return xr.Dataset(
        {
            "coefficient": (("nnm", "mode"), coef, {"units": "1", "long_name": "NNM on the linear modes (Eq. 20)"}),
            "phase_spread": (
                "nnm",
                spread,
                {"units": "deg", "long_name": "largest phase deviation among terms of one frequency"},
            ),
            "shape": (("x", "nnm"), lm["phi"].values @ coef.T, {"units": "kg^-0.5", "long_name": "NNM lateral shape"}),
            "u": ("nnm", coef @ lm["u"].values, {"units": "kg^-0.5", "long_name": "NNM axial tip motion"}),
            "y_s": ("nnm", coef @ lm["y_s"].values, {"units": "kg^-0.5", "long_name": "NNM string stretch"}),
            "theta_s": (
                "nnm",
                coef @ lm["theta_s"].values,
                {"units": "rad kg^-0.5", "long_name": "NNM pendulum angle"},
            ),
            "q": (("nnm", "time"), q, {"units": "kg^0.5 m", "long_name": "NNM coordinates (Eq. 19)"}),
            "q_ddot": (("nnm", "time"), qdd, {"units": "kg^0.5 m/s^2", "long_name": "NNM accelerations"}),
            "drive_measured": (
                "time",
                measured,
                {"units": "m/s^2", "long_name": "measured driving-point acceleration"},
            ),
            "drive_reconstructed": (
                "time",
                recon,
                {"units": "m/s^2", "long_name": "driving-point acceleration from the NNMs (Fig. 5)"},
            ),
        },
        coords={"nnm": ["w", "3w"], "mode": lm["mode"].values, "x": lm["x"], "time": raw["time"]},
        attrs={
            "reconstruction_nrmse": nrmse(recon, measured),
            "phase_limit_deg": phase_limit_deg,
            "excitation_frequency_hz": f0,
            "complex_modes": int(np.any(spread > phase_limit_deg)),
            "n_harmonics": n_harmonics,
        },
    )


def reduced_model_dataset(
    nnm: xr.Dataset, linear_modes: xr.Dataset, raw: xr.Dataset, structure_cfg: Mapping, n_harmonics: int
) -> xr.Dataset:
    """Return the Galerkin reduced model on the NNMs (Eqs. 10-12) and the paper's S(t), N(t) by force-state mapping.

    Parameters
    ----------
    nnm
        The nonlinear modes' dataset (``nonlinear_modes_dataset``): ``coefficient``, ``q`` and ``q_ddot`` are read.
    linear_modes
        The linear chain's modes (results/linear/linear_modes.nc): the stiffnesses of ``linear_model`` and the
        number of modes.
    raw
        The load case's dual-sine record (``io.read_raw``): ``force`` [N] and ``acceleration`` [m/s^2] over
        ``time`` [s], the attributes ``sampling_rate_hz`` and ``excitation_frequency_hz``.
    structure_cfg
        The config's ``structure`` block.
    n_harmonics
        Harmonics K of the excitation frequency kept of the force.

    Returns
    -------
    reduced : xr.Dataset
        The reduced mass, stiffness and force over ``nnm``, and S, N_dyn [N], xi, eta [m] over ``time``, mean
        removed.
    """
    force, acc, fs, f0 = _record(raw)
    model = linear_model(structure_cfg, linear_modes)
    phi = structural_modes(model, linear_modes.sizes["mode"]).shapes
    vectors = phi @ nnm["coefficient"].values.T
    t = raw["time"].values
    f_syn = synthesize(fourier_series(force, fs, f0, n_harmonics), f0, t, 0)[0]
    g = galerkin_contact_forces(model, vectors, nnm["q"].values, nnm["q_ddot"].values, f_syn)
    centre = lambda x: x - x.mean()  # noqa: E731
    return xr.Dataset(
        {
            "reduced_mass": (
                ("nnm", "nnm_"),
                g["reduced_mass"],
                {"units": "1", "long_name": "generalized mass (Eq. 12)"},
            ),
            "reduced_stiffness": (
                ("nnm", "nnm_"),
                g["reduced_stiffness"],
                {"units": "1/s^2", "long_name": "generalized stiffness without contact springs"},
            ),
            "reduced_force": (
                "nnm",
                g["reduced_force"],
                {"units": "kg^-0.5", "long_name": "generalized force of a unit force at d_p"},
            ),
            "S": (
                "time",
                centre(g["S"]),
                {"units": "N", "long_name": "friction force S(t), paper's chain, mean removed"},
            ),
            "N_dyn": (
                "time",
                centre(g["N_dyn"]),
                {"units": "N", "long_name": "dynamic normal force, paper's chain, mean removed"},
            ),
            "xi": ("time", centre(g["xi"]), {"units": "m", "long_name": "xi(t) from the NNMs, mean removed"}),
            "eta": ("time", centre(g["eta"]), {"units": "m", "long_name": "eta(t) from the NNMs, mean removed"}),
        },
        coords={"nnm": ["w", "3w"], "nnm_": ["w", "3w"], "time": raw["time"]},
        attrs={"method": "paper: Galerkin on two NNMs, force-state mapping (Eqs. 10-12, 20)"},
    )


def _stiffness_interval_spreads(
    model: FEModel, modal: xr.Dataset, stiction: xr.Dataset, k_t: float, k_n: float, record, n_harmonics: int
) -> dict:
    """Return {"k_n" | "k_t": {quantity: NRMSE}}: how far S, N_dyn, xi and eta move over a stiffness interval.

    Between the two ends of the linear chain's stiffness interval (N/m) of k_n (an open upper end: 10 x the larger of
    k_n and the lower end) and of k_t, the other stiffness held; ``record``: (force, acceleration, fs, f0) of
    ``_record``.
    """
    force, acc, fs, f0 = record
    lo_n, hi_n = (float(v) for v in stiction["k_n_interval"].values)
    hi_n = hi_n if np.isfinite(hi_n) else 10 * max(k_n, lo_n)
    spreads = {}
    for name, (a, b) in {"k_n": (lo_n, hi_n), "k_t": tuple(float(v) for v in stiction["k_t_interval"].values)}.items():
        res = []
        for val in (a, b):
            ch = {"k_t": val, "k_n": k_n} if name == "k_t" else {"k_t": k_t, "k_n": val}
            m2 = assemble(model.params.with_contact(**ch))
            res.append(
                inverse_identification(
                    m2, modal_damping_vector(m2, modal["damping_ratio"].values), force, acc, fs, f0, n_harmonics
                )
            )
        spreads[name] = {q: nrmse(getattr(res[0], q), getattr(res[1], q)) for q in ("S", "N_dyn", "xi", "eta")}
    return spreads


def _structure_spreads(inv, structures, modal: xr.Dataset, record, n_harmonics: int) -> dict:
    """Return {quantity: largest relative change} of S, N_dyn, xi and eta over ``structures`` (StructureParameters).

    On the harmonics (the relative norm of the coefficients is the NRMSE of the periodic signals; no time synthesis
    needed); empty without structures.
    """
    structure_spread = {}
    if structures:
        force, acc, fs, f0 = record
        F_coef = fourier_series(force, fs, f0, n_harmonics)[0]
        A_coef = fourier_series(acc, fs, f0, n_harmonics)
        own = {"S": inv.S_coef, "N_dyn": inv.N_coef, "xi": inv.xi_coef, "eta": inv.eta_coef}
        for p in structures:
            m = assemble(p)
            h = inverse_harmonics(m, modal_damping_vector(m, modal["damping_ratio"].values), F_coef, A_coef, f0)
            other = {"S": h.S, "N_dyn": h.N_dyn, "xi": m.xi_vector @ h.q, "eta": h.eta}
            for q, c in own.items():
                change = float(np.linalg.norm(other[q] - c) / max(np.linalg.norm(c), 1e-300))
                structure_spread[q] = max(structure_spread.get(q, 0.0), change)
    return structure_spread


def _normal_stiffness_and_hardening(inv) -> tuple[float, float]:
    """Return (k1 in N/m, k2 in N/m^2) of the N-eta relation N_dyn = -k1 eta + k2 eta^2 (eta^2 mean removed).

    Fitted by least squares.
    """
    A = np.column_stack([-inv.eta, inv.eta**2 - np.mean(inv.eta**2)])
    k1, k2 = np.linalg.lstsq(A, inv.N_dyn, rcond=None)[0]
    return k1, k2


def _contact_force_variables(inv, paper: xr.Dataset, k_t: float, k_n: float, dxi, deta) -> dict:
    """Return the contact forces dataset's variables: both methods' S, N_dyn (N), xi, eta (m), and more.

    The working method's rates, the paper's error terms k_t dxi and k_n deta (N) and the sensor misfit per harmonic.
    """
    return {
        "S": ("time", inv.S, {"units": "N", "long_name": "friction force S(t), working method, mean removed"}),
        "N_dyn": (
            "time",
            inv.N_dyn,
            {"units": "N", "long_name": "dynamic normal force N(t) - N0, working method, mean removed"},
        ),
        "xi": ("time", inv.xi, {"units": "m", "long_name": "xi(t), working method, mean removed"}),
        "eta": ("time", inv.eta, {"units": "m", "long_name": "eta(t), working method, mean removed"}),
        "xi_dot": ("time", inv.xi_dot, {"units": "m/s", "long_name": "d xi/dt, working method"}),
        "eta_dot": ("time", inv.eta_dot, {"units": "m/s", "long_name": "d eta/dt, working method"}),
        "S_paper": ("time", paper["S"].values, {"units": "N", "long_name": "S(t), paper's chain"}),
        "N_dyn_paper": ("time", paper["N_dyn"].values, {"units": "N", "long_name": "N(t) - N0, paper's chain"}),
        "xi_paper": ("time", paper["xi"].values, {"units": "m", "long_name": "xi(t), paper's chain"}),
        "eta_paper": ("time", paper["eta"].values, {"units": "m", "long_name": "eta(t), paper's chain"}),
        "k_t_dxi": ("time", k_t * dxi, {"units": "N", "long_name": "k_t dxi: the part of S the stuck NNMs miss"}),
        "k_n_deta": ("time", k_n * deta, {"units": "N", "long_name": "k_n deta: the part of N the stuck NNMs add"}),
        "residual": ("harmonic", inv.residual, {"units": "1", "long_name": "relative sensor misfit per harmonic"}),
    }


def _truth_scores(inv, paper: xr.Dataset, truth: xr.Dataset) -> tuple[dict, dict]:
    """Return (attributes, variables) against the rig's truth.

    Both methods' NRMSE of S, N, xi and eta, and the true S, N - N0 (N), xi and eta (m) with their means removed.
    """
    attrs = {}
    tS, tN, txi, teta = (truth[k].values for k in ("S", "N", "xi", "eta"))
    for method, (S, N, xi, eta) in {
        "": (inv.S, inv.N_dyn, inv.xi, inv.eta),
        "paper_": (paper["S"].values, paper["N_dyn"].values, paper["xi"].values, paper["eta"].values),
    }.items():
        attrs.update(
            {
                f"{method}S_nrmse": nrmse(S, tS),
                f"{method}N_nrmse": nrmse(N, tN),
                f"{method}xi_nrmse": nrmse(xi, txi),
                f"{method}eta_nrmse": nrmse(eta, teta),
            }
        )
    data = {
        "S_truth": ("time", tS - tS.mean(), {"units": "N", "long_name": "true S, mean removed"}),
        "N_dyn_truth": ("time", tN - tN.mean(), {"units": "N", "long_name": "true N - N0, mean removed"}),
        "xi_truth": ("time", txi - txi.mean(), {"units": "m", "long_name": "true xi, mean removed"}),
        "eta_truth": ("time", teta - teta.mean(), {"units": "m", "long_name": "true eta, mean removed"}),
    }
    return attrs, data


def contact_forces_dataset(
    raw: xr.Dataset,
    paper: xr.Dataset,
    linear_modes: xr.Dataset,
    modal: xr.Dataset,
    stiction: xr.Dataset,
    structure_cfg: Mapping,
    n_harmonics: int,
    truth: xr.Dataset | None,
    observability_limit: float = 0.1,
    structures: Sequence[StructureParameters] = (),
) -> xr.Dataset:
    """Return the contact forces of both methods side by side, with their sensitivity and their errors.

    The working method (per-harmonic inverse identification) and the paper's chain; the paper's error decomposed into
    k_t dxi and k_n deta; the working method's sensitivity to the linear chain's stiffness intervals and to
    ``structures`` (the structures the random test allows, ``UpdatingResult.posterior_structures``: E, masses,
    transducers and lever arm within their posterior, which the k_t, k_n intervals alone miss); eta is called
    unobservable when it moves by more than ``observability_limit`` NRMSE across them; errors against the truth.

    Parameters
    ----------
    raw
        The load case's dual-sine record (``io.read_raw``): ``force`` [N] and ``acceleration`` [m/s^2] over
        ``time`` [s], the attributes ``sampling_rate_hz`` and ``excitation_frequency_hz``.
    paper
        The paper's chain's reduced-model dataset (``reduced_model_dataset``): its ``S``, ``N_dyn``, ``xi`` and
        ``eta`` are read.
    linear_modes
        The linear chain's modes (results/linear/linear_modes.nc): ``k_t``, ``k_n`` [N/m] and the stiffnesses of
        ``linear_model``.
    modal
        The modal fit's dataset (results/linear/modal.nc): its ``damping_ratio`` per identified mode is read.
    stiction
        The stiffness fit's dataset (results/linear/stiction.nc): ``k_t_interval`` (both ends finite) and
        ``k_n_interval`` (an open upper end allowed) [N/m] are read.
    structure_cfg
        The config's ``structure`` block.
    n_harmonics
        Harmonics K of the excitation frequency identified.
    truth
        The rig's truth of the record (``S``, ``N``, ``xi``, ``eta`` over ``time``), or None for a measured record.
    observability_limit
        The largest NRMSE by which eta may move over the stiffness intervals and ``structures`` and still be called
        observable (nonlinear.observability_limit) [-].
    structures
        The structures the random test allows (model updating's posterior); empty for none.

    Returns
    -------
    forces : xr.Dataset
        Both methods' S, N_dyn [N], xi, eta [m] over ``time``, the working method's rates [m/s], the paper's error
        terms and the sensor misfit over ``harmonic``; the truth's signals where given; the attributes hold the
        spreads, the N-eta fit and the NRMSEs.
    """
    record = _record(raw)
    force, acc, fs, f0 = record
    model = linear_model(structure_cfg, linear_modes)
    zeta = modal_damping_vector(model, modal["damping_ratio"].values)
    inv = inverse_identification(model, zeta, force, acc, fs, f0, n_harmonics)
    # sensitivity to the stiffness intervals of the linear chain
    k_t, k_n = float(linear_modes["k_t"]), float(linear_modes["k_n"])
    spreads = _stiffness_interval_spreads(model, modal, stiction, k_t, k_n, record, n_harmonics)
    eta_spread = max(spreads["k_n"]["eta"], spreads["k_t"]["eta"])
    # the largest change over the structures the random test allows, per quantity
    structure_spread = _structure_spreads(inv, structures, modal, record, n_harmonics)
    if structure_spread:
        spreads["structure"] = structure_spread
    eta_observable = max(eta_spread, structure_spread.get("eta", 0.0)) <= observability_limit
    # the paper's error explained: S_paper ~ S - k_t dxi, N_paper ~ N_dyn + k_n deta
    dxi = inv.xi - paper["xi"].values
    deta = inv.eta - paper["eta"].values
    S_expl = inv.S - k_t * dxi
    N_expl = inv.N_dyn + k_n * deta
    k1, k2 = _normal_stiffness_and_hardening(inv)
    attrs = {
        "method": "inverse: per-harmonic unknown-input identification with the identified linear model",
        "n_harmonics": n_harmonics,
        "excitation_frequency_hz": f0,
        "eta_observable": int(eta_observable),
        "eta_spread_over_stiffness_intervals": eta_spread,
        "eta_spread_over_structures": structure_spread.get("eta", float("nan")),
        "normal_stiffness_from_n_eta_n_per_m": float(k1),
        "normal_hardening_n_per_m2": float(k2),
        "paper_S_decomposition_nrmse": nrmse(paper["S"].values, S_expl),
        "paper_N_decomposition_nrmse": nrmse(paper["N_dyn"].values, N_expl),
        "paper_xi_unrepresented_fraction": nrmse(paper["xi"].values, inv.xi),
        **{f"spread_{p}_{q}": v for p, d in spreads.items() for q, v in d.items()},
    }
    data = _contact_force_variables(inv, paper, k_t, k_n, dxi, deta)
    if truth is not None:
        truth_attrs, truth_data = _truth_scores(inv, paper, truth)
        attrs.update(truth_attrs)
        data.update(truth_data)
    return xr.Dataset(data, coords={"time": raw["time"], "harmonic": np.arange(1, n_harmonics + 1)}, attrs=attrs)


def harmonic_study(
    raw: xr.Dataset,
    truth: xr.Dataset,
    linear_modes: xr.Dataset,
    modal: xr.Dataset,
    structure_cfg: Mapping,
    counts: Iterable[int],
) -> "pandas.DataFrame":  # noqa: F821
    """Return the working method's errors against the truth for several harmonic counts K.

    Beside the truth's own truncation floor (its S kept to K harmonics).

    Parameters
    ----------
    raw
        The load case's dual-sine record (``io.read_raw``): ``force`` [N] and ``acceleration`` [m/s^2] over
        ``time`` [s], the attributes ``sampling_rate_hz`` and ``excitation_frequency_hz``.
    truth
        The rig's truth of the record: ``S``, ``N``, ``xi`` and ``eta`` over ``time``.
    linear_modes
        The linear chain's modes (results/linear/linear_modes.nc): the stiffnesses of ``linear_model``.
    modal
        The modal fit's dataset (results/linear/modal.nc): its ``damping_ratio`` per identified mode is read.
    structure_cfg
        The config's ``structure`` block.
    counts
        The harmonic counts K to try.

    Returns
    -------
    errors : pandas.DataFrame
        One row per K: ``K``, the NRMSE of S, N, xi and eta (``S_nrmse``...) and ``S_truncation_floor``, all
        relative.
    """
    import pandas as pd

    force, acc, fs, f0 = _record(raw)
    model = linear_model(structure_cfg, linear_modes)
    zeta = modal_damping_vector(model, modal["damping_ratio"].values)
    t = raw["time"].values
    rows = []
    for K in counts:
        inv = inverse_identification(model, zeta, force, acc, fs, f0, int(K))
        S_trunc = synthesize(fourier_series(truth["S"].values, fs, f0, int(K)), f0, t, 0)[0]
        rows.append(
            {
                "K": int(K),
                "S_nrmse": nrmse(inv.S, truth["S"].values),
                "N_nrmse": nrmse(inv.N_dyn, truth["N"].values),
                "xi_nrmse": nrmse(inv.xi, truth["xi"].values),
                "eta_nrmse": nrmse(inv.eta, truth["eta"].values),
                "S_truncation_floor": nrmse(S_trunc, truth["S"].values),
            }
        )
    return pd.DataFrame(rows)
