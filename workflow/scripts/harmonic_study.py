"""Rule harmonic_study: working-method errors against truth versus the harmonic count K."""

from pathlib import Path

from contactid.io import load_dataset, read_raw
from contactid.logs import setup_logging
from contactid.nonlinear_chain import harmonic_study

log = setup_logging(snakemake.log[0])
inp = snakemake.input
df = harmonic_study(
    read_raw(inp.raw, dual_sine=True),
    load_dataset(inp.truth),
    load_dataset(inp.modes),
    load_dataset(inp.modal),
    snakemake.params.structure,
    snakemake.params.counts,
)
Path(snakemake.output.table).parent.mkdir(parents=True, exist_ok=True)
df.to_csv(snakemake.output.table, index=False, float_format="%.6g")
log.info("\n%s", df.to_string())
