"""Rule generalized_coordinates: p''(t) from the sensors, Fourier series, p(t) (Eqs. 15-17)."""

from contactid.io import load_dataset, provenance, read_raw, write_dataset
from contactid.logs import setup_logging
from contactid.nonlinear_chain import generalized_coordinates_dataset

log = setup_logging(snakemake.log[0])
K = int(snakemake.params.nonlinear["n_harmonics"])
raw = read_raw(snakemake.input.raw, dual_sine=True)
ds = generalized_coordinates_dataset(raw, load_dataset(snakemake.input.modes), K)
ds.attrs.update(
    provenance(
        "generalized_coordinates", {"n_harmonics": K}, {"raw": snakemake.input.raw, "modes": snakemake.input.modes}
    )
)
write_dataset(ds, snakemake.output.gc)
