"""Rule gap_benchmark: gather the blind items into accuracy, confusion matrix, false alarms, shrink."""

import json

from contactid.gap.bench_scores import confusion_figure, records_check_score, score
from contactid.gap.output import json_ready
from contactid.io import write_text
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
rows = [json.load(open(path)) for path in snakemake.input.rows]
result = score(rows)
# the records' check (rule record_checks) on records that are all right: its false alarms
result["records_check"] = records_check_score(rows)
# one line per item: the single-effect items' shrink, the compound items' effects and explanation, a failure's reason
KEYS = {
    "blind": ("shrink_true",),
    "effect_free": ("shrink_true",),
    "leave_out": ("shrink_true",),
    "compound": ("effects", "named", "updating_accepted", "friction_errors"),
}
result["items"] = [
    {
        k: r[k]
        for k in (
            "item",
            "effect",
            "magnitude",
            "seed",
            "kind",
            "verdict",
            "seconds",
            *(("failed",) if r.get("failed") else ("heldout_gap_before", "records_check", *KEYS[r["kind"]])),
        )
    }
    for r in rows
]
write_text(snakemake.output.summary, json.dumps(json_ready(result), indent=2))
labels = list(result["confusion"])
cols = sorted({c for row in result["confusion"].values() for c in row}, key=lambda c: (c == "none", c))
lines = ["true," + ",".join(cols)]
lines += [t + "," + ",".join(str(result["confusion"][t].get(c, 0)) for c in cols) for t in labels]
write_text(snakemake.output.confusion, "\n".join(lines) + "\n")
confusion_figure(result, snakemake.output.figure)
log.info(
    "top-1 accuracy %.3f over %d, false alarms %d of %d",
    result["top1_accuracy"],
    result["n_blind"],
    result["false_alarms"],
    result["n_effect_free"],
)
