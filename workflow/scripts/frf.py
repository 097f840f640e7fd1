"""Rule frf: H1 and coherence of each accelerometer over the force (Welch).

The random test is validated first (format, clipping, record length, FRF resolution) and the coherence
after (share of lines in modal.band_hz reaching raw_checks.min_coherence); warnings go into the dataset.
"""

import json

from contactid.io import provenance, read_raw, write_dataset
from contactid.linear_chain import check_sensor_layout, frf_dataset
from contactid.logs import fmt, setup_logging
from contactid.raw_checks import check_settings
from contactid.raw_checks_random import (
    driving_point_sign_warnings,
    validate_coherence,
    validate_random_test,
)

log = setup_logging(snakemake.log[0])
p = snakemake.params
path = snakemake.input.raw
checks = check_settings(p.checks)
seg = int(p.frf["segment_length"])  # the validated config holds the schema's defaults
raw = read_raw(path)
check_sensor_layout(raw, p.structure, path)
warnings = validate_random_test(raw, path, checks, seg, int(p.blocks))
ds = frf_dataset(raw, seg, float(p.frf["overlap"]), p.frf["window"], int(p.blocks))
shares, coherence_warnings = validate_coherence(ds, p.band_hz, path, checks)
warnings += coherence_warnings
warnings += driving_point_sign_warnings(ds, float(p.structure["excitation_position_m"]), p.band_hz)
ds.attrs["warnings"] = json.dumps(warnings)
ds.attrs["coherence_share"] = json.dumps(shares)
ds.attrs.update(
    provenance("frf", {"frf": p.frf, "blocks": p.blocks, "checks": checks, "band_hz": p.band_hz}, {"raw": path})
)
write_dataset(ds, snakemake.output.frf)
for w in warnings:
    log.warning("%s: %s", path, w)
log.info(
    "FRF with %d averages; share of lines with coherence >= %g: %s",
    ds.attrs["n_averages"],
    checks["min_coherence"],
    fmt(shares, 3),
)
