# contactid: identification of frictional and normal contact forces at a
# micro-vibro-impacting joint (Pourahmadian, Ahmadian & Jalali, JSV 2012).
# The only Snakefile: it validates the config and includes the rule files.

from snakemake.utils import min_version, validate

min_version("9.0")


configfile: "config/config.yaml"


validate(config, "workflow/schemas/config.schema.yaml")


include: "workflow/rules/common.smk"
include: "workflow/rules/rig.smk"
include: "workflow/rules/linear.smk"
include: "workflow/rules/outputs.smk"


rule all:
    input:
        all_outputs(),
    default_target: True
