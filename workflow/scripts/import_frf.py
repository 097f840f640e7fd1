"""Rule import_uff58_frf: measured FRFs (UFF58) -> results/linear/frf.nc.

The UFF58 datasets of function type 4 (accelerance, with coherence where given) become the dataset the frf rule
writes from a time record.

The frequency axis is checked (even, covering modal.band_hz), then the FRF checks that need no time record: the
resolution (raw_checks.max_frf_resolution_hz) and the coherence in the modal band; warnings go into the dataset.
"""

import json

from contactid.importers.frf_uff import measured_frf_dataset
from contactid.io import provenance, write_dataset
from contactid.logs import fmt, setup_logging
from contactid.raw_checks import check_settings
from contactid.raw_checks_random import validate_coherence, validate_frf_resolution

log = setup_logging(snakemake.log[0])
p = snakemake.params
path = snakemake.input.file
checks = check_settings(p.checks)
ds = measured_frf_dataset(p.block, "random_test", p.structure, p.band_hz)
warnings = validate_frf_resolution(ds, path, checks)
shares, coherence_warnings = validate_coherence(ds, p.band_hz, path, checks)
warnings += coherence_warnings
ds.attrs["warnings"] = json.dumps(warnings)
ds.attrs["coherence_share"] = json.dumps(shares)
ds.attrs.update(
    provenance("import_uff58_frf", {"block": p.block, "checks": checks, "band_hz": p.band_hz}, {"file": path})
)
write_dataset(ds, snakemake.output.frf)
for w in warnings:
    log.warning("%s: %s", path, w)
log.info(
    "FRFs of %s imported from %s (%s lines, %.6g Hz apart; coherence given: %s); share of lines with coherence "
    ">= %g: %s",
    [str(s) for s in ds["sensor"].values],
    path,
    ds.sizes["frequency"],
    ds.attrs["frequency_resolution_hz"],
    ds.attrs["coherence_given"],
    checks["min_coherence"],
    fmt(shares, 3),
)
