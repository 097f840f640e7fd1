"""Rule gap_report_fragment: the report's section on the sim-to-real gap (and the blind benchmark)."""

import json
from pathlib import Path

from contactid.gap.report import gap_section
from contactid.io import write_text
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
diag = json.loads(Path(snakemake.input.diagnosis).read_text())
bench = json.loads(Path(snakemake.input.benchmark).read_text()) if "benchmark" in snakemake.input.keys() else None
intervals = json.loads(Path(snakemake.input.intervals).read_text()) if "intervals" in snakemake.input.keys() else None
write_text(snakemake.output.tex, gap_section(diag, bench, intervals))
log.info("gap section written (benchmark %s)", "included" if bench else "not built")
