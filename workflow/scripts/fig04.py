"""Rule fig04_generalized_coordinates (Fig. 4)."""

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.paper_figures import plot_fig04

setup_logging(snakemake.log[0])
plot_fig04(load_dataset(snakemake.input.gc), snakemake.params.case, snakemake.output.png, snakemake.output.pdf)
