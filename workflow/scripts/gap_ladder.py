"""Rule gap_ladder: the detection ladder's items scored (named and refitted magnitude where detectable)."""

import json

from contactid.gap.bench_scores import ladder_score
from contactid.gap.floor import read_floor, resolved_gap_config
from contactid.gap.output import json_ready
from contactid.io import write_text
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
rows = [json.load(open(path)) for path in snakemake.input.rows]
# gap.min_gap, or with gap.measure_floor the one rule gap_benchmark_floor measured
floor = resolved_gap_config({"min_gap": snakemake.params.floor}, read_floor(snakemake.input))["min_gap"]
result = ladder_score(rows, float(floor))
write_text(snakemake.output[0], json.dumps(json_ready(result), indent=2))
log.info(
    "detection ladder: %d items, %d detectable (held-out gap above twice the floor); named in %s, refitted "
    "magnitude within 25 %% in %s of them",
    result["n"],
    result["n_detectable"],
    result["named_where_detectable"],
    result["magnitude_within_where_detectable"],
)
for i in result["items"]:
    log.info(
        "%s: gap %.3g%s -> %s, refitted %s",
        i["item"],
        i.get("heldout_gap_before", float("nan")),
        " (detectable)" if i.get("detectable") else "",
        i.get("verdict"),
        i.get("refitted_magnitude"),
    )
