"""Rule noise_study_point: one point of the noise / record-length study (rig records, identification, errors)."""

import json

from contactid.io import write_text
from contactid.logs import setup_logging
from contactid.studies import run_point

log = setup_logging(snakemake.log[0])
p = snakemake.params.point
row = run_point(snakemake.params.config, float(p["noise_fraction"]), int(p["record_samples"]), int(p["seed"]))
write_text(snakemake.output.point, json.dumps(row, indent=1))
log.info(
    "noise %g, %d samples, seed %d: errors mu %.3g, e0 %.3g, k_t %.3g",
    row["noise_fraction"],
    row["record_samples"],
    row["seed"],
    row["error_mu"],
    row["error_e0"],
    row["error_k_t"],
)
