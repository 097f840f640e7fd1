"""Rule nonlinear_modes: the two real NNMs of Eq. 20, the phase check and Fig. 5's reconstruction."""

from contactid.io import load_dataset, provenance, read_raw, write_dataset
from contactid.logs import fmt, setup_logging
from contactid.nonlinear_chain import nonlinear_modes_dataset

log = setup_logging(snakemake.log[0])
nl = snakemake.params.nonlinear
K, limit = int(nl["n_harmonics"]), float(nl["phase_limit_deg"])
raw = read_raw(snakemake.input.raw, dual_sine=True)
ds = nonlinear_modes_dataset(
    load_dataset(snakemake.input.gc), load_dataset(snakemake.input.modes), raw, snakemake.params.structure, K, limit
)
if ds.attrs["complex_modes"]:
    log.warning(
        "NNM phase spread %s deg exceeds %s deg: the modes are complex, the real-NNM assumption "
        "of Section 4 does not hold",
        fmt(ds["phase_spread"].values, 3),
        limit,
    )
ds.attrs.update(
    provenance(
        "nonlinear_modes", nl, {"raw": snakemake.input.raw, "gc": snakemake.input.gc, "modes": snakemake.input.modes}
    )
)
write_dataset(ds, snakemake.output.nnm)
