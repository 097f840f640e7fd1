"""Rules frf_measured_uff / frf_synthesised_uff: every sensor's FRFs as UFF58 datasets.

The measured H1 FRFs with their coherence, or the FRFs the identified modes synthesise (LSFD), as UFF58 datasets
(function types 4 and 6) for other modal tools; read back by pyuff and by the uff58_frf importer.
"""

import json

from contactid.frf_synthesis import synthesised_frf
from contactid.importers.frf_export import write_frf_uff58
from contactid.io import load_dataset
from contactid.linear_chain import complex_frf
from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
frf = load_dataset(snakemake.input.frf)
sensors = [str(s) for s in frf["sensor"].values]
reference = sensors.index(frf.attrs["driving_point_sensor"])
if snakemake.params.kind == "synthesised":
    h = synthesised_frf(frf, load_dataset(snakemake.input.modal))
    coherence = None
    what = "contactid LSFD synthesis"
else:
    h = complex_frf(frf)
    given = json.loads(frf.attrs.get("coherence_given", "{}"))  # an imported FRF may come without coherence
    coherence = [c if given.get(s, True) else None for s, c in zip(sensors, frf["coherence"].values)]
    what = "contactid H1"
write_frf_uff58(snakemake.output.uff, frf["frequency"].values, h, sensors, coherence, what, reference)
log.info("%s FRFs of %s written to %s (%d lines)", what, sensors, snakemake.output.uff, frf.sizes["frequency"])
