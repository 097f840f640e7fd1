"""Rule rig_dual_sine: response-controlled dual-sine test of one load case (raw + truth)."""

from contactid.io import provenance, write_dataset
from contactid.logs import setup_logging
from contactid.rig.dual_sine import dual_sine_test

log = setup_logging(snakemake.log[0])
p = snakemake.params
case = snakemake.wildcards.case
raw, truth = dual_sine_test(
    p.structure,
    p.rig,
    p.case_cfg,
    float(p.sampling_rate_hz),
    float(p.rig["noise_fraction"]),
    int(p.seed),
    case,
    p.structure["sensors"]["names"],
)
cfg = {"seed": p.seed, "structure": p.structure, "rig": p.rig, "case": p.case_cfg, "fs": p.sampling_rate_hz}
raw.attrs.update(provenance("rig_dual_sine", cfg))
truth.attrs.update(provenance("rig_dual_sine", cfg))
write_dataset(truth, snakemake.output.truth)
write_dataset(raw, snakemake.output.raw)
residual = truth.attrs.get("energy_energy_residual")
log.info(
    "%s: F1 = %.4g N, F3 = %.4g N, A1 = %.5g, A2 = %.5g m/s^2 (targets %.5g, %.5g), %s",
    case,
    truth.attrs["F1_n"],
    truth.attrs["F3_n"],
    truth.attrs["A1_m_per_s2"],
    truth.attrs["A2_m_per_s2"],
    truth.attrs["target_A1_m_per_s2"],
    truth.attrs["target_A2_m_per_s2"],
    # a drifting preload does work of its own over the record: no balance is taken then (rig.dual_sine)
    f"energy residual {residual:.3g}" if residual is not None else "no energy balance (the preload drifts)",
)
