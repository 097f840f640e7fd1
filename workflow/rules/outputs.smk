# Outputs for people: tables, figures and the headline numbers.


rule paper_consistency:
    output:
        table=report(
            "results/tables/paper_consistency.csv",
            caption="../report/paper_consistency.rst",
            category="Tables",
        ),
    params:
        structure=config["structure"],
        truth=config.get("rig", {}).get("truth", {}),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/paper_consistency.log",
    benchmark:
        "benchmarks/rules/paper_consistency.tsv"
    script:
        "../scripts/paper_consistency.py"


rule linear_tables:
    input:
        modal="results/linear/modal.nc",
        stiction="results/linear/stiction.nc",
        truth=random_test_truth(),
    output:
        table1=report("results/tables/table1.csv", caption="../report/table1.rst", category="Tables"),
        table3=report("results/tables/table3.csv", caption="../report/table3.rst", category="Tables"),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/linear_tables.log",
    script:
        "../scripts/linear_tables.py"


rule fig03_frf:
    input:
        frf="results/linear/frf.nc",
        modal="results/linear/modal.nc",
    output:
        png=report("results/figures/fig03_frf.png", caption="../report/fig03.rst", category="Figures"),
        pdf="results/figures/fig03_frf.pdf",
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/fig03_frf.log",
    script:
        "../scripts/fig03_frf.py"


rule summary:
    input:
        unpack(summary_inputs),
    output:
        summary="results/summary.json",
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/summary.log",
    script:
        "../scripts/summary.py"
