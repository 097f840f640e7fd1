"""Rule gap_diagnosis: the identified model against every load case's raw record (issue 7)."""

import dataclasses
import json
import time

from contactid.gap.candidates import load_plugins
from contactid.gap.diagnosis import diagnose
from contactid.gap.explain import updated_model_summary, with_damping_at_test_level
from contactid.gap.floor import read_floor, resolved_gap_config
from contactid.gap.localise import linear_stage, random_test_delays
from contactid.gap.output import diagnosis_json, gap_dataset, updated_model_json
from contactid.gap.pipeline import workflow_models
from contactid.gap.record_checks import diagnosis_outcome
from contactid.gap.settings import GapSettings
from contactid.gap.story_decisions import records_agree
from contactid.gap.workers import prepare_workers
from contactid.io import load_dataset, provenance, write_dataset, write_text
from contactid.logs import setup_logging
from contactid.test_damping import damping_summary

log = setup_logging(snakemake.log[0])
p = snakemake.params
inp = snakemake.input
t0 = time.perf_counter()
load_plugins(p.gap.get("plugins"))
K = int(p.n_harmonics)
# gap.measure_floor: min_gap from the floor the rule gap_floor measured
floor = read_floor(inp)
gap = resolved_gap_config(p.gap, floor)
settings = GapSettings.from_config(gap, int(p.seed), K)
workers = int(snakemake.resources.workers)
prepare_workers(workers)  # before the friction fit after updating starts numba's threads
records, fit_settings, modal, chain_model, model, updating = workflow_models(
    p.structure, inp, p.cases, p.calibration_case, K, p.friction, settings, int(p.seed)
)
frf = load_dataset(inp.frf)
linear = linear_stage(model, frf, modal)
diag = diagnose(
    model,
    records,
    p.calibration_case,
    settings,
    fit_settings,
    linear,
    workers=workers,
    identified=chain_model,
    updating=updating,
    channel_delays=random_test_delays(frf, modal),
)
# records that contradict each other or the model by a units factor, a sign or a channel order: no effect is looked for
with open(inp.record_checks) as fh:
    record_check = json.load(fh)
verdict, reason, explanation = diagnosis_outcome(diag.verdict, diag.reason, diag.explanation, record_check)
if verdict != diag.verdict and not explanation:  # records that disagree: no effect explained, no model updated by one
    diag = dataclasses.replace(
        diag, updated_model=updated_model_summary(chain_model, model, None, [], diag.where["heldout_gap_before"])
    )
diag = dataclasses.replace(
    diag,
    verdict=verdict,
    reason=reason,
    explanation=explanation,
    trace=[*diag.trace, records_agree(record_check).as_dict()],
)
# the damping at test level (rule test_damping) where the held-out records confirm it and no effect explains the gap
updated = with_damping_at_test_level(
    diag.updated_model, damping_summary(load_dataset(inp.test_damping)), diag.explanation, model.preload
)
diag = dataclasses.replace(diag, updated_model=updated)
seconds = time.perf_counter() - t0
prov = provenance(
    "gap_diagnosis",
    {"gap": p.gap, "structure": p.structure, "friction": p.friction, "seed": p.seed},
    {
        "modes": inp.modes,
        "modal": inp.modal,
        "frf": inp.frf,
        "fit": inp.fit,
        "test_damping": inp.test_damping,
        **{f"raw_{c}": path for c, path in zip(p.cases, inp.raw)},
    },
)
ds = gap_dataset(diag, records, settings.n_harmonics)
ds.attrs.update(prov)
write_dataset(ds, snakemake.output.dataset)
extra = {
    "seconds": seconds,
    "provenance": prov,
    "records_check": record_check,
    "damping_at_test_level": updated.get("damping_at_test_level"),
}
if floor is not None:
    extra["measured_floor"] = floor
write_text(snakemake.output.diagnosis, diagnosis_json(diag, extra))
write_text(snakemake.output.updated_model, updated_model_json(diag.updated_model, {"provenance": prov}))
log.info("verdict %s: %s (%.1f s)", diag.verdict, diag.reason, seconds)
