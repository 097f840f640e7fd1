"""Rule summary: the headline numbers in results/summary.json."""

import json

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.reporting import linear_summary

log = setup_logging(snakemake.log[0])
truth = load_dataset(snakemake.input.truth) if snakemake.input.get("truth") else None
summary = linear_summary(load_dataset(snakemake.input.modal), load_dataset(snakemake.input.stiction), truth)
with open(snakemake.output.summary, "w") as fh:
    json.dump(summary, fh, indent=2, sort_keys=True)
log.info("%s", summary)
