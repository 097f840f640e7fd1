"""Rule contact_forces: the working method and the paper's chain side by side, scored against truth."""

import json

from contactid.io import load_dataset, provenance, read_raw, write_dataset
from contactid.logs import fmt, setup_logging
from contactid.nonlinear_chain import contact_forces_dataset
from contactid.parameters import identified_structure
from contactid.updating import UpdatingResult

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
ds = contact_forces_dataset(
    read_raw(inp.raw, dual_sine=True),
    load_dataset(inp.reduced),
    modes,
    load_dataset(inp.modal),
    load_dataset(inp.stiction),
    snakemake.params.structure,
    K,
    truth,
    float(nl["observability_limit"]),
    structures,
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
