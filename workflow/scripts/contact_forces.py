"""Rule contact_forces: the working method and the paper's chain side by side, scored against truth."""

import json

import numpy as np
from contactid.io import RawDataError, load_dataset, nonfinite_variables, provenance, read_raw, write_dataset
from contactid.logs import fmt, setup_logging
from contactid.nonlinear_chain import contact_forces_dataset
from contactid.parameters import identified_structure
from contactid.updating_result import UpdatingResult

log = setup_logging(snakemake.log[0])
inp, nl = snakemake.input, snakemake.params.nonlinear
K = int(nl["n_harmonics"])
truth = load_dataset(inp.truth) if "truth" in inp.keys() else None
modes = load_dataset(inp.modes)
structures = ()
if "updating" in inp.keys():  # the structures the random test allows (model updating's posterior)
    with open(inp.updating) as fh:
        upd = json.load(fh)
    if upd["enabled"]:
        nominal = identified_structure(snakemake.params.structure, modes)
        structures = UpdatingResult.from_summary(upd, nominal).posterior_structures()


# an open interval end is inf by design: k_n's, which the chain closes itself, is no sign of a NaN's origin
OPEN_BY_DESIGN = ("k_n_interval",)
raw = read_raw(inp.raw, dual_sine=True)
reduced, modal, stiction = load_dataset(inp.reduced), load_dataset(inp.modal), load_dataset(inp.stiction)
inputs = {inp.raw: raw, inp.reduced: reduced, inp.modes: modes, inp.modal: modal, inp.stiction: stiction}
# the stiffness intervals' ends are structures the chain assembles (_stiffness_interval_spreads): an open upper end of
# k_t (inf: the random test does not bound it) would give a NaN stiffness matrix; k_n's open end is closed there
if not np.all(np.isfinite(stiction["k_t_interval"].values)):
    raise RawDataError(
        f"contact forces of {inp.raw}: {inp.stiction}'s k_t_interval is {stiction['k_t_interval'].values.tolist()} N/m "
        f"(k_t = {float(stiction['k_t']):.4g} N/m; the random test's natural frequencies do not bound the tangential "
        "contact stiffness from both sides), and the contact forces' spread over it needs both ends. Check the "
        "random test (its sampling rate and units) and the structure's description; the stiffness fit's log "
        "(logs/stiction_stiffness.log) says how far its frequencies are from the structure's"
    )
try:
    ds = contact_forces_dataset(
        raw,
        reduced,
        modes,
        modal,
        stiction,
        snakemake.params.structure,
        K,
        truth,
        float(nl["observability_limit"]),
        structures,
    )
except (ValueError, np.linalg.LinAlgError) as exc:  # a NaN in a matrix: scipy's check, or a solver that fails on it
    bad = nonfinite_variables(inputs, skip=OPEN_BY_DESIGN)
    if isinstance(exc, RawDataError) or not (bad or "infs or NaNs" in str(exc)):
        raise
    raise RawDataError(
        f"contact forces of {inp.raw}: the inverse identification failed on infs or NaNs ({type(exc).__name__}: "
        f"{exc}); "
        + (
            "non-finite inputs: " + "; ".join(bad)
            if bad
            else "every input is finite, so the identified structure itself (k_t, k_n, the structures the model "
            f"updating allows in {inp.updating if 'updating' in inp.keys() else 'none'}) makes it singular"
        )
        + ". Check the random test (its sampling rate and units) and the linear chain's logs"
    ) from exc
bad = [
    name
    for name, var in ds.data_vars.items()
    if np.asarray(var.values).dtype.kind in "fc" and not np.all(np.isfinite(var.values))
]
if bad:
    raise RawDataError(
        f"contact forces of {inp.raw}: the identified {', '.join(bad)} hold infs or NaNs (not written to "
        f"{snakemake.output.forces}); non-finite inputs: "
        + ("; ".join(nonfinite_variables(inputs, skip=OPEN_BY_DESIGN)) or "none")
        + ". Check the random test (its sampling rate and units) and the linear chain's logs"
    )
if not ds.attrs["eta_observable"]:
    log.warning(
        "eta moves by %.0f %% across the linear chain's stiffness intervals and by %.0f %% across the "
        "structures the random test allows: it is not observable from these sensors; N(t) is (spread %.2g)",
        100 * ds.attrs["eta_spread_over_stiffness_intervals"],
        100 * ds.attrs["eta_spread_over_structures"],
        ds.attrs["spread_k_n_N_dyn"],
    )
ds.attrs.update(
    provenance(
        "contact_forces", {"structure": snakemake.params.structure, "nonlinear": nl}, {k: v for k, v in inp.items()}
    )
)
write_dataset(ds, snakemake.output.forces)
log.info("NRMSE %s", fmt({k.removesuffix("_nrmse"): v for k, v in ds.attrs.items() if "nrmse" in k}))
