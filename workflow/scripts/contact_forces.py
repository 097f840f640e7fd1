"""Rule contact_forces: the working method and the paper's chain side by side, scored against truth."""

from contactid.io import load_dataset, provenance, read_raw, write_dataset
from contactid.logs import fmt, setup_logging
from contactid.nonlinear_chain import contact_forces_dataset

log = setup_logging(snakemake.log[0])
inp, nl = snakemake.input, snakemake.params.nonlinear
K = int(nl.get("n_harmonics", 25))
truth = load_dataset(inp.truth) if "truth" in inp.keys() else None
ds = contact_forces_dataset(read_raw(inp.raw, dual_sine=True), load_dataset(inp.reduced), load_dataset(inp.modes),
                            load_dataset(inp.modal), load_dataset(inp.stiction), snakemake.params.structure, K, truth,
                            float(nl.get("observability_limit", 0.1)))
if not ds.attrs["eta_observable"]:
    log.warning("eta moves by %.0f %% across the linear chain's stiffness intervals: it is not observable from "
                "these sensors; N(t) is (spread %.2g)", 100 * ds.attrs["eta_spread_over_stiffness_intervals"],
                ds.attrs["spread_k_n_N_dyn"])
ds.attrs.update(provenance("contact_forces", {"structure": snakemake.params.structure, "nonlinear": nl},
                           {k: v for k, v in inp.items()}))
write_dataset(ds, snakemake.output.forces)
log.info("NRMSE %s", fmt({k.removesuffix("_nrmse"): v for k, v in ds.attrs.items() if "nrmse" in k}))
