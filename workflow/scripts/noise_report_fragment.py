"""Rule noise_report_fragment: the report's section on the noise / record-length study."""

from contactid.io import load_dataset, write_text
from contactid.logs import setup_logging
from contactid.studies import report_section

setup_logging(snakemake.log[0])
ds = load_dataset(snakemake.input.dataset) if "dataset" in snakemake.input.keys() else None
write_text(snakemake.output.tex, report_section(ds))
