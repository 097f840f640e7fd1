"""Rule frf: H1 and coherence of each accelerometer over the force (Welch)."""

from contactid.io import provenance, read_raw, write_dataset
from contactid.linear_chain import check_sensor_layout, frf_dataset
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
p = snakemake.params
raw = read_raw(snakemake.input.raw)
check_sensor_layout(raw, p.structure, snakemake.input.raw)
ds = frf_dataset(raw, int(p.frf.get("segment_length", 16384)), float(p.frf.get("overlap", 0.5)),
                 p.frf.get("window", "hann"), int(p.blocks))
ds.attrs.update(provenance("frf", {"frf": p.frf, "blocks": p.blocks}, {"raw": snakemake.input.raw}))
write_dataset(ds, snakemake.output.frf)
log.info("FRF with %d averages", ds.attrs["n_averages"])
