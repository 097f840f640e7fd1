"""Rule fig05_reconstruction (Fig. 5)."""

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.paper_figures import plot_fig05

setup_logging(snakemake.log[0])
plot_fig05(load_dataset(snakemake.input.nnm), snakemake.params.case, snakemake.output.png, snakemake.output.pdf)
