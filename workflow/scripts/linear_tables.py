"""Rule linear_tables: Tables 1 and 3 (identified, paper, rig truth, % differences)."""

from pathlib import Path

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.reporting import table1, table3

log = setup_logging(snakemake.log[0])
truth = load_dataset(snakemake.input.truth) if snakemake.input.get("truth") else None
t1 = table1(load_dataset(snakemake.input.modal), truth)
t3 = table3(load_dataset(snakemake.input.stiction), truth)
Path(snakemake.output.table1).parent.mkdir(parents=True, exist_ok=True)
t1.to_csv(snakemake.output.table1, index=False, float_format="%.6g")
t3.to_csv(snakemake.output.table3, index=False, float_format="%.6g")
log.info("\n%s\n%s", t1.to_string(), t3.to_string())
