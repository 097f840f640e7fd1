"""Rule friction_intervals: the friction law's intervals with a model-form term (issue 15, item 6)."""

import json

from contactid.gap.floor import read_floor, resolved_gap_config
from contactid.gap.pipeline import workflow_models
from contactid.gap.settings import GapSettings
from contactid.gap.uncertainty import friction_uncertainty
from contactid.io import write_text
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
p = snakemake.params
inp = snakemake.input
K = int(p.n_harmonics)
# gap.measure_floor: min_gap from the floor the rule gap_floor measured
floor = read_floor(inp)
gap = resolved_gap_config(p.gap, floor)
settings = GapSettings.from_config(gap, int(p.seed), K)
records, fit_settings, modal, _, model, upd = workflow_models(
    p.structure, inp, p.cases, p.calibration_case, K, p.friction, settings, int(p.seed)
)
unc = friction_uncertainty(
    model, records, p.calibration_case, fit_settings, int(p.seed), upd.posterior_structures() if upd is not None else ()
)
par = unc.summary()
out = {
    "model": "updated" if upd is not None and upd.accepted else "chain",
    "calibration_case": p.calibration_case,
    "load_cases": list(p.cases),
    "n_structures": len(unc.structure_fits),
    "parameters": par,
}
write_text(snakemake.output[0], json.dumps(out, indent=2, default=float))
log.info(
    "friction intervals with model form: %s",
    ", ".join(f"{n} [{v['interval'][0]:.4g}, {v['interval'][1]:.4g}]" for n, v in par.items() if n != "confidence"),
)
