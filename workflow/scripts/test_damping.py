"""Rule test_damping: the driven mode's damping at test level.

Profiled by the friction law's misfit on the calibration record and applied where the other load cases confirm it.
"""

from contactid.friction_fit import settings_from_config
from contactid.friction_parameters import parameter_dataset
from contactid.gap.damping import test_level_damping
from contactid.gap.model import identified_model
from contactid.gap.pipeline import workflow_records
from contactid.gap.settings import GapSettings
from contactid.io import load_dataset, provenance, write_dataset
from contactid.logs import setup_logging
from contactid.test_damping import profile_dataset

log = setup_logging(snakemake.log[0])
p, inp = snakemake.params, snakemake.input
K = int(p.nonlinear["n_harmonics"])
fit_settings = settings_from_config(p.friction)
settings = GapSettings.from_config(p.gap, int(p.seed), K)
modal = load_dataset(inp.modal)
unfitted = parameter_dataset([1.0] * 5, fit_settings.regularization)
model = identified_model(p.structure, load_dataset(inp.modes), modal, unfitted)
records = workflow_records(inp.raw, p.cases, K)
held_out = {c: r for c, r in records.items() if c != p.calibration_case}
profile = test_level_damping(
    model,
    records[p.calibration_case],
    held_out,
    fit_settings,
    settings,
    int(p.seed),
    sorted({1.0, *p.nonlinear["test_damping_scales"]}),
)
ds = profile_dataset(profile, modal["damping_ratio"].values)
ds.attrs.update(
    provenance(
        "test_damping",
        {"structure": p.structure, "friction": p.friction, "nonlinear": p.nonlinear, "gap": p.gap, "seed": p.seed},
        {"modes": inp.modes, "modal": inp.modal, **{f"raw_{c}": path for c, path in zip(p.cases, inp.raw)}},
    )
)
write_dataset(ds, snakemake.output.damping)
