"""Rule gap_figures: one figure per question of the diagnosis (PDF too for those the report includes)."""

from contactid.gap.figures import all_figures
from contactid.gap.place import PlaceThresholds
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
all_figures(
    snakemake.input.diagnosis,
    snakemake.input.dataset,
    dict(snakemake.output.items()),
    PlaceThresholds.from_config(snakemake.params.place),
)
log.info("gap figures written")
