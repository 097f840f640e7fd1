"""Rule stiction_stiffness: k_t and k_n of Eq. 13 fitted to the natural frequencies."""

from contactid.io import load_dataset, provenance, write_dataset
from contactid.linear_chain import stiction_dataset
from contactid.logs import fmt, setup_logging
from contactid.model_checks import stiffness_fit_check
from contactid.parameters import structure_from_config
from contactid.stiction_refusal import random_test_source, refuse_unreachable

log = setup_logging(snakemake.log[0])
p = snakemake.params
modal = load_dataset(snakemake.input.modal)
ds = stiction_dataset(modal, p.structure, p.stiction)
# a record the described structure cannot have come from (frequencies out of its reach, FRF amplitudes far from its
# masses') stops here, before linear_modes, the contact forces, the model updating and the gap diagnosis build on it
# (and overwrite the results of a good record)
refuse_unreachable(
    structure_from_config(p.structure, 1e7, 1e8),
    ds,
    p.stiction,
    *random_test_source(modal, p.random_test),
    residue_abs=modal["residue_abs"].values if "residue_abs" in modal else None,
)
ds.attrs.update(
    provenance(
        "stiction_stiffness", {"structure": p.structure, "stiction": p.stiction}, {"modal": snakemake.input.modal}
    )
)
write_dataset(ds, snakemake.output.stiction)
log.info(
    "k_t = %.4g N/m, interval %s; k_n = %.4g N/m, interval %s",
    float(ds["k_t"]),
    fmt(ds["k_t_interval"].values),
    float(ds["k_n"]),
    fmt(ds["k_n_interval"].values),
)
check = stiffness_fit_check(ds.attrs["chi2_min"], ds.sizes["mode"], ds.attrs["confidence"])
if check is not None:
    (log.info if check["passed"] else log.warning)("%s", check["message"])
