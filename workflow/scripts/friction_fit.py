"""Rule friction_fit: GA + polish of the modified Valanis law on the calibration case (Table 4)."""

from contactid.friction_datasets import friction_fit_dataset
from contactid.friction_fit import settings_from_config
from contactid.friction_parameters import fitted_parameters
from contactid.io import load_dataset, provenance, write_dataset
from contactid.logs import fmt, setup_logging
from contactid.model_checks import friction_fit_check

log = setup_logging(snakemake.log[0])
p = snakemake.params
forces = load_dataset(snakemake.input.forces)
ds = friction_fit_dataset(
    forces, float(p.preload), settings_from_config(p.friction), int(p.seed), int(p.n_harmonics), paper_forces=forces
)
ds.attrs.update(
    provenance(
        "friction_fit",
        {"friction": p.friction, "seed": p.seed, "preload": p.preload, "n_harmonics": p.n_harmonics},
        {"forces": snakemake.input.forces},
    )
)
write_dataset(ds, snakemake.output.fit)
log.info(
    "fitted %s; e0(N0) = %.4g N/m, misfit %.4g",
    fmt(dict(zip(ds["parameter"].values, fitted_parameters(ds)))),
    ds.attrs["e0_at_preload_n_per_m"],
    ds.attrs["misfit_nrmse"],
)
check = friction_fit_check(ds.attrs["misfit_nrmse"], ds.attrs["misfit_floor"])
(log.info if check["passed"] else log.warning)("%s", check["message"])
