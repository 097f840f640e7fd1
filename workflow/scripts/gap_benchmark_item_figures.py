"""Rule gap_benchmark_item_figures: a benchmark item's gap figures and report section, as `snakemake gap` draws them."""

import json
from pathlib import Path

from contactid.gap.figures import all_figures, failed_item_figures
from contactid.gap.place import PlaceThresholds
from contactid.gap.report import gap_section
from contactid.io import write_text
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
diag = json.loads(Path(snakemake.input.diagnosis).read_text())
out = {k: v for k, v in snakemake.output.items() if k != "tex"}
if diag.get("failed"):  # the rig could not simulate the item: every figure says so
    failed_item_figures(diag["failed"], out)
    write_text(snakemake.output.tex, f"% benchmark item not diagnosed: {diag['failed']}\n")
else:
    all_figures(
        snakemake.input.diagnosis, snakemake.input.dataset, out, PlaceThresholds.from_config(snakemake.params.place)
    )
    write_text(snakemake.output.tex, gap_section(diag, None))
log.info("%s: gap figures and section written", snakemake.wildcards.item)
