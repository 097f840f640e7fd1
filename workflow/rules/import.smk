# Importers: measured records in the files test rigs write, converted to the raw netCDF format.
# One rule per source format; the channel map (units, sensitivities, positions) is explicit in the
# config (UFF58, TDMS) or in the CSV's sidecar YAML (config/README.md, "Importing measured files").


rule import_uff58:
    input:
        unpack(import_inputs),
    output:
        raw="data/imported/{record}.nc",
    wildcard_constraints:
        record=import_pattern("uff58"),
    params:
        code=CODE_DIGEST,
        block=lambda wc: record_block(wc.record),
        where=lambda wc: wc.record if wc.record == "random_test" else f"load_cases.{wc.record}",
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/import_{record}.log",
    script:
        "../scripts/import_record.py"


rule import_tdms:
    input:
        unpack(import_inputs),
    output:
        raw="data/imported/{record}.nc",
    wildcard_constraints:
        record=import_pattern("tdms"),
    params:
        code=CODE_DIGEST,
        block=lambda wc: record_block(wc.record),
        where=lambda wc: wc.record if wc.record == "random_test" else f"load_cases.{wc.record}",
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/import_{record}.log",
    script:
        "../scripts/import_record.py"


rule import_csv:
    input:
        unpack(import_inputs),
    output:
        raw="data/imported/{record}.nc",
    wildcard_constraints:
        record=import_pattern("csv"),
    params:
        code=CODE_DIGEST,
        block=lambda wc: record_block(wc.record),
        where=lambda wc: wc.record if wc.record == "random_test" else f"load_cases.{wc.record}",
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/import_{record}.log",
    script:
        "../scripts/import_record.py"
