"""Rules import_uff58 / import_tdms / import_csv: one measured file -> a raw record (netCDF)."""

from contactid.importers import import_record
from contactid.io import file_digest, provenance, write_dataset
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
p = snakemake.params
record = snakemake.wildcards.record
raw = import_record(p.block, p.where, dual_sine=record != "random_test")
raw.attrs.update(provenance(snakemake.rule, dict(p.block), {k: v for k, v in snakemake.input.items()}))
raw.attrs["source_sha256"] = file_digest(snakemake.input.file)
write_dataset(raw, snakemake.output.raw)
log.info(
    "%s: %d samples at %g Hz from %s (%s)",
    record,
    raw.sizes["time"],
    raw.attrs["sampling_rate_hz"],
    snakemake.input.file,
    raw.attrs["conversion"],
)
