"""Rule fig06_contact_forces (Fig. 6): both methods' S-xi and N-eta loops per load case."""

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.paper_figures import plot_fig06

setup_logging(snakemake.log[0])
forces = {c: load_dataset(p) for c, p in zip(snakemake.params.cases, snakemake.input.forces)}
plot_fig06(forces, snakemake.output.png, snakemake.output.pdf)
