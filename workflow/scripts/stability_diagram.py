"""Rule stability_diagram: the LSCF poles over model order with the chosen poles (results/figures/stability)."""

from pathlib import Path

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.modal_figures import consecutive_stable_orders, plot_stability

log = setup_logging(snakemake.log[0])
Path(snakemake.output.png).parent.mkdir(parents=True, exist_ok=True)
modal = load_dataset(snakemake.input.modal)
poles = plot_stability(load_dataset(snakemake.input.frf), modal, snakemake.output.png, snakemake.output.pdf)
order = int(modal.attrs["order"])
for fn in modal["natural_frequency"].values:
    n = consecutive_stable_orders(poles, float(fn), order)
    log.info("mode at %.3f Hz: stable in frequency, damping and vector over the last %d orders (to %d)", fn, n, order)
