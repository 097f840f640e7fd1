# Sim-to-real gap diagnosis (issue 7): the identified model against the records, localised,
# explained by the candidate library; and its blind check on rig data with a hidden effect.


rule gap:
    input:
        gap_outputs(),


rule model_updating:
    input:
        modal="results/linear/modal.nc",
        modes="results/linear/linear_modes.nc",
    output:
        "results/gap/model_updating.json",
    params:
        code=CODE_DIGEST,
        structure=config["structure"],
        gap=config["gap"],
        seed=config["seed"],
        n_harmonics=config["nonlinear"]["n_harmonics"],
    threads: 1
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/model_updating.log",
    script:
        "../scripts/model_updating.py"


rule friction_intervals:
    """The friction law's 95 % intervals with a model-form term: the spread of refits over the other load cases and
    over the structures the random test allows (results/gap/friction_intervals.json)."""
    input:
        unpack(gap_inputs),
    output:
        "results/gap/friction_intervals.json",
    params:
        code=CODE_DIGEST,
        structure=config["structure"],
        gap=config["gap"],
        friction=config["friction"],
        seed=config["seed"],
        n_harmonics=config["nonlinear"]["n_harmonics"],
        calibration_case=calibration_case(),
        cases=load_cases(),
    threads: 1
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/friction_intervals.log",
    script:
        "../scripts/friction_intervals.py"


rule gap_diagnosis:
    priority: CRITICAL_PATH
    input:
        unpack(gap_inputs),
    output:
        diagnosis="results/gap/diagnosis.json",
        dataset="results/gap/gap.nc",
    params:
        code=CODE_DIGEST,
        structure=config["structure"],
        gap=config["gap"],
        friction=config["friction"],
        seed=config["seed"],
        n_harmonics=config["nonlinear"]["n_harmonics"],
        calibration_case=calibration_case(),
        cases=load_cases(),
    # one thread for the scheduler, so that the job starts as soon as the fit is done (a two-thread job waits
    # until both cores are free, and the figures and tables kept one busy: 24 s lost), and one BLAS thread (Snakemake
    # sets them to the threads; the many small solves ran 49 s with two against 11 s with one); its candidates
    # run in `workers` forked processes beside the jobs that finish the figures (a resource, not a parameter:
    # the results do not depend on it, and a changed --cores must not rerun the job)
    threads: 1
    resources:
        workers=min(2, workflow.cores),
        runtime=20,
        mem_mb=2000,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_diagnosis.log",
    benchmark:
        "benchmarks/rules/gap_diagnosis.tsv"
    script:
        "../scripts/gap_diagnosis.py"


rule gap_figures:
    input:
        diagnosis="results/gap/diagnosis.json",
        dataset="results/gap/gap.nc",
    output:
        stages=report("results/gap/gap_stages.png", caption="../report/gap.rst", category="Gap diagnosis"),
        harmonics=report("results/gap/gap_harmonics.png", caption="../report/gap.rst", category="Gap diagnosis"),
        cycle=report("results/gap/gap_cycle.png", caption="../report/gap.rst", category="Gap diagnosis"),
        force_state=report("results/gap/gap_force_state.png", caption="../report/gap.rst", category="Gap diagnosis"),
        ranking=report("results/gap/gap_ranking.png", caption="../report/gap.rst", category="Gap diagnosis"),
        shrink=report("results/gap/gap_shrink.png", caption="../report/gap.rst", category="Gap diagnosis"),
        explanation=report("results/gap/gap_explanation.png", caption="../report/gap.rst", category="Gap diagnosis"),
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_figures.log",
    script:
        "../scripts/gap_figures.py"


rule gap_benchmark_item:
    output:
        item="results/gap_benchmark/items/{item}.json",
    params:
        code=CODE_DIGEST,
        spec=lambda wc: {**benchmark_items(), **ladder_items()}[wc.item],
        config=benchmark_base_config(),
    wildcard_constraints:
        item=r"[a-z_]+-[0-9]+-s[0-9]+",
    threads: 1
    resources:
        runtime=20,
        mem_mb=2000,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_benchmark/{item}.log",
    script:
        "../scripts/gap_benchmark_item.py"


rule gap_benchmark:
    input:
        rows=expand("results/gap_benchmark/items/{item}.json", item=list(benchmark_items())),
    output:
        summary="results/gap_benchmark/benchmark.json",
        confusion=report("results/gap_benchmark/confusion.csv", caption="../report/gap_benchmark.rst", category="Gap diagnosis"),
        figure=report("results/gap_benchmark/confusion.png", caption="../report/gap_benchmark.rst", category="Gap diagnosis"),
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_benchmark.log",
    script:
        "../scripts/gap_benchmark.py"


rule gap_ladder:
    """The detection ladder: every effect at a tenth, a third and the whole of its typical magnitude, scored where
    its held-out gap exceeds twice gap.min_gap (results/gap_benchmark/ladder.json)."""
    input:
        rows=expand("results/gap_benchmark/items/{item}.json", item=list(ladder_items())),
    output:
        "results/gap_benchmark/ladder.json",
    params:
        code=CODE_DIGEST,
        floor=config["gap"]["min_gap"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_ladder.log",
    script:
        "../scripts/gap_ladder.py"


rule gap_report_fragment:
    input:
        unpack(gap_report_inputs),
    output:
        tex="results/report/gap.tex",
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_report_fragment.log",
    script:
        "../scripts/gap_report_fragment.py"
