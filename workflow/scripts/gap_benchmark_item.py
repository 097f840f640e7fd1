"""Rule gap_benchmark_item: one blind data set: rig records with a hidden effect -> chain -> diagnosis."""

import json

import numba
from contactid.gap.benchmark import run_item
from contactid.gap.floor import read_floor, resolved_gap_config
from contactid.gap.output import json_ready
from contactid.io import write_text
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
numba.set_num_threads(max(1, min(int(snakemake.threads), numba.config.NUMBA_NUM_THREADS)))
config = dict(snakemake.params.config)
# gap.measure_floor: min_gap from the floor the rule gap_benchmark_floor measured
config["gap"] = resolved_gap_config(config["gap"], read_floor(snakemake.input))
row = run_item(
    snakemake.params.spec,
    config,
    {"diagnosis": snakemake.output.diagnosis, "dataset": snakemake.output.dataset},
)
row["item"] = snakemake.wildcards.item
write_text(snakemake.output.item, json.dumps(json_ready(row), indent=2))
log.info("%s: effect %s (%.4g) -> verdict %s", row["item"], row["effect"], row["magnitude"], row["verdict"])
