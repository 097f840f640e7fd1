"""Rule modal: natural frequencies and damping ratios from the FRFs (LSCF/LSFD)."""

from contactid.io import load_dataset, provenance, write_dataset
from contactid.linear_chain import modal_dataset
from contactid.logs import fmt, setup_logging

log = setup_logging(snakemake.log[0])
m = snakemake.params.modal
ds = modal_dataset(load_dataset(snakemake.input.frf), int(m["n_modes"]), m["band_hz"], int(m["order"]))
ds.attrs.update(provenance("modal", m, {"frf": snakemake.input.frf}))
write_dataset(ds, snakemake.output.modal)
log.info("natural frequencies %s Hz", fmt(ds["natural_frequency"].values, 5))
