"""Rule raw_check: read and check a dual-sine record (rig or measured); harmonic content."""

from contactid.io import provenance, read_raw, write_dataset
from contactid.linear_chain import check_sensor_layout
from contactid.logs import setup_logging
from contactid.raw_checks import dual_sine_check_dataset

log = setup_logging(snakemake.log[0])
p = snakemake.params
path = snakemake.input.raw
max_h = int(p.checks.get("max_harmonic", 15))
raw = read_raw(path, dual_sine=True, min_periods=int(p.checks.get("min_periods", 8)), max_harmonic=max_h)
check_sensor_layout(raw, p.structure, path)
ds = dual_sine_check_dataset(raw, p.structure, path, max_h)
ds.attrs.update(provenance("raw_check", p.checks, {"raw": path}))
write_dataset(ds, snakemake.output.check)
log.info("%s: A1 = %.4g, A2 = %.4g m/s^2 at %.4g Hz", path, ds.attrs["A1_m_per_s2"], ds.attrs["A2_m_per_s2"],
         ds.attrs["excitation_frequency_hz"])
