"""Rule linear_modes: mass-normalised linear modes of the identified linear model."""

from contactid.io import load_dataset, provenance, write_dataset
from contactid.linear_chain import linear_modes_dataset
from contactid.logs import fmt, setup_logging

log = setup_logging(snakemake.log[0])
p = snakemake.params
ds = linear_modes_dataset(
    load_dataset(snakemake.input.stiction),
    p.structure,
    int(p.linear_modes["n_modes"]),
    int(p.linear_modes["grid_points"]),
    float(p.k_n_prior),
)
ds.attrs.update(
    provenance(
        "linear_modes",
        {"structure": p.structure, "linear_modes": p.linear_modes, "k_n_prior": p.k_n_prior},
        {"stiction": snakemake.input.stiction},
    )
)
write_dataset(ds, snakemake.output.modes)
log.info("linear modes at %s Hz (k_n: %s)", fmt(ds["natural_frequency"].values, 5), ds.attrs["k_n_choice"])
