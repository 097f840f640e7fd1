"""Rule raw_check: read and validate a dual-sine record (rig, measured or imported); harmonic content.

A failed check (format, length, clipping, excitation frequency, stationarity) stops this load case with
a message naming the file, the channel, the check and the measured value; warnings go into the dataset.
"""

import json

from contactid.io import load_dataset, provenance, read_raw, write_dataset
from contactid.linear_chain import check_sensor_layout
from contactid.logs import setup_logging
from contactid.raw_checks import check_settings
from contactid.raw_checks_dual_sine import dual_sine_check_dataset, frf_level_check, validate_dual_sine

log = setup_logging(snakemake.log[0])
p = snakemake.params
path = snakemake.input.raw
checks = check_settings(p.checks)
max_h = int(checks["max_harmonic"])
raw = read_raw(
    path, dual_sine=True, min_periods=int(checks["min_periods"]), max_harmonic=max(max_h, int(p.n_harmonics))
)
check_sensor_layout(raw, p.structure, path)
warnings = validate_dual_sine(raw, path, checks)
ds = dual_sine_check_dataset(raw, p.structure, path, max_h)
# the record's level against the random test's FRF: a record in other units than its label stops here
ds.attrs["level_factor_to_frf"] = frf_level_check(ds, load_dataset(snakemake.input.frf), path)
ds.attrs["warnings"] = json.dumps(warnings)
ds.attrs.update(
    provenance("raw_check", {"checks": checks, "n_harmonics": p.n_harmonics}, {"raw": path, "frf": snakemake.input.frf})
)
write_dataset(ds, snakemake.output.check)
for w in warnings:
    log.warning("%s: %s", path, w)
log.info(
    "%s: A1 = %.4g, A2 = %.4g m/s^2 at %.4g Hz",
    path,
    ds.attrs["A1_m_per_s2"],
    ds.attrs["A2_m_per_s2"],
    ds.attrs["excitation_frequency_hz"],
)
