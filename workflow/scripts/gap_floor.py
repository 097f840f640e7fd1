"""Rules gap_floor and gap_benchmark_floor: the identification's own floor of the held-out gap (gap.measure_floor).

gap_floor: at the calibration record's drive, with the identified friction law as the rig's truth.
gap_benchmark_floor: at the configured drive, with the configured rig's law (the benchmark items' rig).
"""

import json
import math

from contactid.friction_parameters import fitted_parameters
from contactid.gap.floor import identification_floor, response_targets
from contactid.gap.records import record_harmonics
from contactid.io import load_dataset, read_raw, write_text
from contactid.logs import setup_logging
from contactid.schema import with_defaults

log = setup_logging(snakemake.log[0])
cfg = with_defaults(snakemake.params.config)
inp = snakemake.input
if "fit" in inp.keys():  # the configured data: the calibration record's drive, the identified law
    fit = load_dataset(inp.fit)
    friction, regularization = fitted_parameters(fit), str(fit.attrs["regularization"])
    st = cfg["structure"]
    for case, path in zip(snakemake.params.cases, inp.raw):
        lc = cfg["load_cases"][case]
        if "A1_m_per_s2" not in lc or "A2_m_per_s2" not in lc:  # a measured case: its levels from its record
            cfg["load_cases"][case] = response_targets(
                read_raw(path, dual_sine=True), st["sensors"]["positions_m"], st["excitation_position_m"]
            )
            log.info("floor: %s's response levels from its record: %s", case, cfg["load_cases"][case])
    raw = read_raw(inp.calibration, dual_sine=True)
    rec = record_harmonics(raw, cfg["nonlinear"]["calibration_case"], int(cfg["nonlinear"]["n_harmonics"]))
    f0, fs, n = rec.f0, rec.fs, int(raw.sizes["time"])
else:  # the blind benchmark's items: the configured rig, its law and its drive
    truth = cfg["rig"]["truth"]["friction"]
    friction = [truth[k] for k in ("e_f_n_per_m", "k_c_per_m", "e_t_n_per_m", "kappa", "mu")]
    regularization = truth["regularization"]
    f0 = float(cfg["rig"]["dual_sine"]["excitation_frequency_hz"])
    fs = float(cfg["random_test"]["sampling_rate_hz"])
    n = int(cfg["rig"]["dual_sine"]["record_samples"])
try:
    floor = identification_floor(cfg, friction, regularization, f0, fs, n, int(cfg["seed"]))
except (ValueError, FloatingPointError, ArithmeticError, RuntimeError) as exc:  # the rig or the chain could not
    # make or identify these records (a law the rig cannot drive to the levels, say): the diagnosis goes on with the
    # configured gap.min_gap, and says why
    log.warning("floor: not measured (%s); gap.min_gap as configured", exc)
    floor = {"floor": None, "min_gap": None, "reason": f"not measured: {exc}"}
if floor["floor"] is not None and not math.isfinite(floor["floor"]):
    log.warning("floor: the rig's records gave a held-out gap of %s; gap.min_gap as configured", floor["floor"])
    floor = {**floor, "floor": None, "min_gap": None, "reason": "the floor's rig records were not finite"}
write_text(snakemake.output[0], json.dumps(floor, indent=2))
