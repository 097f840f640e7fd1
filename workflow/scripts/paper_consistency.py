"""Rule paper_consistency: Table 1 against Table 3 and Table 4 under candidate assumptions."""

from pathlib import Path

from contactid.consistency import paper_consistency_table
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
p = snakemake.params
df = paper_consistency_table(p.structure, p.truth.get("friction"))
Path(snakemake.output.table).parent.mkdir(parents=True, exist_ok=True)
df.to_csv(snakemake.output.table, index=False, float_format="%.6g")
log.info("\n%s", df.to_string())
