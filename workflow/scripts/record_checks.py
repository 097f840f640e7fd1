"""Rule record_checks: the load cases' records against each other and against the identified model.

The records against each other (accelerance levels) and against the identified model's prediction at each record's
measured force (units factor, sign, channel order, gross disagreement).
"""

import json

from contactid.gap.pipeline import workflow_record_checks
from contactid.gap.record_checks import Thresholds
from contactid.io import provenance, write_text
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
p = snakemake.params
inp = snakemake.input
check = workflow_record_checks(
    p.structure, inp, p.cases, p.calibration_case, int(p.n_harmonics), Thresholds.from_config(p.thresholds)
)
check["provenance"] = provenance(
    "record_checks",
    {"structure": p.structure, "thresholds": p.thresholds, "n_harmonics": p.n_harmonics},
    {"modes": inp.modes, "modal": inp.modal, "fit": inp.fit, **{f"raw_{c}": r for c, r in zip(p.cases, inp.raw)}},
)
write_text(snakemake.output[0], json.dumps(check, indent=2, default=float) + "\n")
for f in check["findings"]:
    log.warning("RECORDS CHECK: %s", f["message"])
log.info("records check %s (%d findings)", "passed" if check["passed"] else "FAILED", len(check["findings"]))
