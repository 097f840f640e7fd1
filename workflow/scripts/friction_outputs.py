"""Rule friction_outputs: Table 4, Figs. 7-9 and the GA convergence figure."""

from pathlib import Path

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.paper_figures import plot_friction_figures
from contactid.reporting import table4

log = setup_logging(snakemake.log[0])
fit = load_dataset(snakemake.input.fit)
validations = {c: load_dataset(p) for c, p in zip(snakemake.params.cases, snakemake.input.validations)}
t4 = table4(fit, snakemake.params.truth_friction)
Path(snakemake.output.table4).parent.mkdir(parents=True, exist_ok=True)
t4.to_csv(snakemake.output.table4, index=False, float_format="%.6g")
plot_friction_figures(fit, validations, snakemake.params.truth_friction, dict(snakemake.output.items()))
log.info("\n%s", t4.to_string())
