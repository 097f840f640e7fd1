"""Rule validate: the fitted law predicts S(t) of a load case from its own xi(t), N(t)."""

from contactid.friction_datasets import validation_dataset
from contactid.io import load_dataset, provenance, write_dataset
from contactid.logs import fmt, setup_logging

log = setup_logging(snakemake.log[0])
inp = snakemake.input
truth = load_dataset(inp.truth) if "truth" in inp.keys() else None
ds = validation_dataset(
    load_dataset(inp.forces),
    load_dataset(inp.fit),
    float(snakemake.params.preload),
    int(snakemake.params.n_harmonics),
    truth,
)
ds.attrs.update(provenance("validate", {"preload": snakemake.params.preload}, {k: v for k, v in inp.items()}))
write_dataset(ds, snakemake.output.validation)
log.info(
    "validation NRMSE %s", fmt({k.removeprefix("nrmse_"): v for k, v in ds.attrs.items() if k.startswith("nrmse")})
)
