"""Rule reduced_model: Galerkin model on the NNMs and the paper's S(t), N(t) (Eqs. 10-12)."""

from contactid.io import load_dataset, provenance, read_raw, write_dataset
from contactid.logs import setup_logging
from contactid.nonlinear_chain import reduced_model_dataset

log = setup_logging(snakemake.log[0])
K = int(snakemake.params.nonlinear["n_harmonics"])
raw = read_raw(snakemake.input.raw, dual_sine=True)
ds = reduced_model_dataset(
    load_dataset(snakemake.input.nnm), load_dataset(snakemake.input.modes), raw, snakemake.params.structure, K
)
ds.attrs.update(
    provenance(
        "reduced_model",
        {"structure": snakemake.params.structure, "n_harmonics": K},
        {"raw": snakemake.input.raw, "nnm": snakemake.input.nnm, "modes": snakemake.input.modes},
    )
)
write_dataset(ds, snakemake.output.reduced)
