"""Rule noise_study: gather the study's points into a dataset, a table and a figure."""

import json

from contactid.io import provenance, write_dataset
from contactid.logs import setup_logging
from contactid.studies import gather, plot_noise_study

log = setup_logging(snakemake.log[0])
rows = [json.load(open(f)) for f in snakemake.input.points]
ds = gather(rows)
ds.attrs.update(provenance("noise_study", {"default_noise": snakemake.params.default_noise}))
ds.attrs["default_noise_fraction"] = float(snakemake.params.default_noise)
write_dataset(ds, snakemake.output.dataset)
ds.drop_vars("seconds").to_dataframe().to_csv(snakemake.output.table)
plot_noise_study(ds, float(snakemake.params.default_noise), snakemake.output.png, snakemake.output.pdf)
log.info("%d points gathered", len(rows))
