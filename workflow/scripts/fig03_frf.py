"""Rule fig03_frf: every sensor's FRF, measured and LSFD-synthesised, phase and coherence (Fig. 3)."""

from pathlib import Path

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.modal_figures import plot_fig03

setup_logging(snakemake.log[0])
Path(snakemake.output.png).parent.mkdir(parents=True, exist_ok=True)
plot_fig03(
    load_dataset(snakemake.input.frf), load_dataset(snakemake.input.modal), snakemake.output.png, snakemake.output.pdf
)
