"""Rule gap_figures: one figure per view of the diagnosis."""

from contactid.gap.figures import all_figures
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
o = snakemake.output
all_figures(
    snakemake.input.diagnosis,
    snakemake.input.dataset,
    {
        "stages": o.stages,
        "harmonics": o.harmonics,
        "cycle": o.cycle,
        "force_state": o.force_state,
        "ranking": o.ranking,
        "shrink": o.shrink,
        "explanation": o.explanation,
    },
)
log.info("gap figures written")
