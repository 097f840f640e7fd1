"""Rule rig_random_test: simulate the low-level random test (raw + truth)."""

from contactid.io import provenance, write_dataset
from contactid.logs import fmt, setup_logging
from contactid.rig.random_test import random_test_datasets

log = setup_logging(snakemake.log[0])
p = snakemake.params
raw, truth = random_test_datasets(p.structure, p.rig, p.random_test, p.seed)
cfg = {"seed": p.seed, "structure": p.structure, "rig": p.rig, "random_test": p.random_test}
raw.attrs.update(provenance("rig_random_test", cfg))
truth.attrs.update(provenance("rig_random_test", cfg))
write_dataset(truth, snakemake.output.truth)
write_dataset(raw, snakemake.output.raw)
log.info(
    "random test: %d samples, true frequencies %s Hz", raw.sizes["time"], fmt(truth["natural_frequency"].values[:3], 5)
)
