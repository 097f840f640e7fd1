"""Rule model_updating: the base structure updated from the random test's modal fit (issue 15)."""

import json

from contactid.gap.base_model import structure_update
from contactid.gap.settings import GapSettings
from contactid.io import load_dataset, write_text
from contactid.logs import setup_logging
from contactid.parameters import identified_structure
from contactid.schema import with_defaults

log = setup_logging(snakemake.log[0])
p = snakemake.params
modes = load_dataset(snakemake.input.modes)
# the update reads gap.model_updating alone (the rule's params): the block's siblings at their defaults
gap = {**with_defaults({"gap": {}})["gap"], "model_updating": p.model_updating}
settings = GapSettings.from_config(gap, int(p.seed), int(p.n_harmonics))
structure = identified_structure(p.structure, modes)
upd = structure_update(structure, load_dataset(snakemake.input.modal), settings)
summary = {"enabled": upd is not None, **(upd.summary() if upd is not None else {})}
write_text(snakemake.output[0], json.dumps(summary, indent=2, default=float))
if upd is not None:
    log.info(
        "model updating %s: chi2 %.3g -> %.3g (significant above a drop of %.3g, %.2g factors bound); %s; not bound by "
        "the data: %s",
        "accepted" if upd.accepted else "not accepted",
        upd.chi2_nominal,
        upd.chi2_updated,
        upd.chi2_threshold,
        upd.effective_factors,
        ", ".join(f"{k} {v:.4g}" for k, v in upd.factors.items()),
        ", ".join(k for k, v in upd.identifiability.items() if not v["bound_by_data"]) or "none",
    )
    if upd.channel_gains:
        log.info(
            "the channels' gains relative to one another on the residues (the measurement chain's): %s",
            ", ".join(f"{g:.4f} (sd {s:.4f})" for g, s in zip(upd.channel_gains, upd.channel_gain_sd)),
        )
    if upd.structure_alone:
        alone = upd.structure_alone
        log.info(
            "without the gains, the structure's factors alone: chi2 %.3g (%.3g with them, a drop of %.3g against %.3g: "
            "%s); %s",
            alone["chi2_updated"],
            upd.chi2_updated,
            alone["gains_drop"],
            alone["gains_threshold"],
            "the gains are needed" if alone["gains_needed"] else "the random test cannot tell, the records will choose",
            ", ".join(f"{k} {v:.4g}" for k, v in ((alone.get("proposal") or alone)["factors"]).items()),
        )
