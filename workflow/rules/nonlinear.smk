# The dual-sine records of the load cases (Sections 3-5): checks, and later the nonlinear chain.

rule raw_check:
    input:
        raw=lambda wc: raw_record(wc.case),
    output:
        check="results/{case}/raw_check.nc",
    params:
        structure=config["structure"],
        checks=config.get("raw_checks", {}),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/raw_check_{case}.log",
    script:
        "../scripts/raw_check.py"
