# Importers: measured records in the files test rigs write, converted to the raw netCDF format.
# One rule per source format (import_uff58, import_tdms, import_csv); the channel map (units,
# sensitivities, positions) is explicit in the config (UFF58, TDMS) or in the CSV's sidecar YAML
# (config/README.md, "Importing measured files").

for _fmt in ("uff58", "tdms", "csv"):

    rule:
        """One measured record in a test rig's file format (UFF58, TDMS or CSV with its sidecar YAML) converted to the raw netCDF format with its channel map (data/imported/)."""
        name:
            f"import_{_fmt}"
        input:
            unpack(import_inputs),
        output:
            raw="data/imported/{record}.nc",
        wildcard_constraints:
            record=import_pattern(_fmt),
        params:
            code=CODE_DIGEST,
            records=lambda wc: records_digest(list(import_inputs(wc).values())),
            block=lambda wc: record_block(wc.record),
            where=lambda wc: wc.record if wc.record == "random_test" else f"load_cases.{wc.record}",
        conda:
            "../envs/contactid.yaml"
        log:
            "logs/import_{record}.log",
        script:
            "../scripts/import_record.py"
