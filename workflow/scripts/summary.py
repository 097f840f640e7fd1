"""Rule summary: the headline numbers in results/summary.json."""

import json

from contactid.io import load_dataset
from contactid.logs import setup_logging
from contactid.model_checks import model_checks
from contactid.reporting import (
    contact_force_summary,
    friction_summary,
    linear_summary,
    load_case_summary,
    model_form_summary,
    records_check_summary,
)
from contactid.test_damping import damping_summary

log = setup_logging(snakemake.log[0])
inp = snakemake.input
truth = load_dataset(inp.truth) if "truth" in inp.keys() else None
stiction = load_dataset(inp.stiction)
summary = linear_summary(load_dataset(inp.modal), stiction, truth)
checks = {k[len("check_") :]: load_dataset(v) for k, v in inp.items() if k.startswith("check_")}
truths = {k[len("truth_") :]: load_dataset(v) for k, v in inp.items() if k.startswith("truth_")}
summary.update(load_case_summary(checks, truths))
summary["data_warnings"]["random_test"] = json.loads(load_dataset(inp.frf).attrs.get("warnings", "[]"))
forces = {k[len("forces_") :]: load_dataset(v) for k, v in inp.items() if k.startswith("forces_")}
nnms = {k[len("nnm_") :]: load_dataset(v) for k, v in inp.items() if k.startswith("nnm_")}
summary.update(contact_force_summary(forces, nnms))
fit = load_dataset(inp.fit) if "fit" in inp.keys() else None
if fit is not None:
    validations = {k[len("validation_") :]: load_dataset(v) for k, v in inp.items() if k.startswith("validation_")}
    summary.update(friction_summary(fit, validations))
# each fit against the accuracy it assumes (contactid.model_checks); the report's "Model checks" paragraph
summary["model_checks"] = model_checks(stiction.attrs, stiction.sizes["mode"], None if fit is None else fit.attrs)
if "test_damping" in inp.keys():  # the damping at test level (rule test_damping)
    summary["friction"]["test_damping"] = damping_summary(load_dataset(inp.test_damping))
if "friction_intervals" in inp.keys():
    with open(inp.friction_intervals) as fh:
        summary["friction"]["model_form_intervals"] = model_form_summary(json.load(fh))
if "record_checks" in inp.keys():  # the records against each other and the identified model (rule record_checks)
    with open(inp.record_checks) as fh:
        summary["records_check"] = records_check_summary(json.load(fh), summary["data_warnings"])
with open(snakemake.output.summary, "w") as fh:
    json.dump(summary, fh, indent=2, sort_keys=True, default=lambda o: o.item() if hasattr(o, "item") else str(o))
log.info("summary of %s written to %s", ", ".join(summary), snakemake.output.summary)
