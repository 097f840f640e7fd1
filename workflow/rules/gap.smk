# Sim-to-real gap diagnosis (issue 7): the identified model against the records, localised,
# explained by the candidate library; and its blind check on rig data with a hidden effect.


rule gap:
    """Target: the sim-to-real gap diagnosis of the configured data, its figures and report section (results/gap/)."""
    input:
        gap_outputs(),


rule gap_floor:
    """The identification's own floor of the held-out gap at the records' drive, where gap.measure_floor: the rig
    without effects, the identified friction law as its truth, identified again (results/gap/floor.json)."""
    input:
        fit="results/friction/friction_fit.nc",
        calibration=raw_record(calibration_case()),
        raw=[raw_record(c) for c in load_cases()],
    output:
        "results/gap/floor.json",
    params:
        code=CODE_DIGEST,
        records=records_digest([raw_record(c) for c in load_cases()]),
        config=benchmark_base_config(),
        cases=load_cases(),
    threads: 1
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_floor.log",
    script:
        "../scripts/gap_floor.py"


rule gap_benchmark_floor:
    """The blind benchmark's floor of the held-out gap where gap.measure_floor: the configured rig without
    effects at its configured drive, identified (results/gap_benchmark/floor.json)."""
    output:
        "results/gap_benchmark/floor.json",
    params:
        code=CODE_DIGEST,
        config=benchmark_base_config(),
    threads: 1
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_benchmark/floor.log",
    script:
        "../scripts/gap_floor.py"


rule model_updating:
    """Structural updating from the random test's modal data before the gap candidates (results/gap/model_updating.json)."""
    input:
        modal="results/linear/modal.nc",
        modes="results/linear/linear_modes.nc",
    output:
        "results/gap/model_updating.json",
    params:
        code=CODE_DIGEST,
        structure=config["structure"],
        # its block alone: the contact forces and the friction fit read the update, and another gap setting
        # (gap.min_gap, the candidates) reran them
        model_updating=config["gap"]["model_updating"],
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
    priority: CRITICAL_PATH
    input:
        unpack(gap_inputs),
    output:
        "results/gap/friction_intervals.json",
    params:
        code=CODE_DIGEST,
        records=records_digest([raw_record(c) for c in load_cases()]),
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
    """Where the identified model and the records disagree and which unmodelled effect explains it, checked on held-out load cases (results/gap/diagnosis.json, gap.nc)."""
    priority: CRITICAL_PATH
    input:
        unpack(gap_inputs),
        record_checks="results/gap/record_checks.json",
        test_damping="results/friction/test_damping.nc",
    output:
        diagnosis="results/gap/diagnosis.json",
        dataset="results/gap/gap.nc",
        updated_model="results/gap/updated_model.json",
    params:
        code=CODE_DIGEST,
        records=records_digest([raw_record(c) for c in load_cases()]),
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
    """The gap diagnosis' figures, one per question: the gap by stage, the candidates ranked, before and after per held-out case and the explanation (PNG, and PDF at the report's text width), and the diagnostic views by harmonic and sensor, by part of the cycle and the force-state maps (results/gap/*.png)."""
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
        stages_pdf="results/gap/gap_stages.pdf",
        ranking_pdf="results/gap/gap_ranking.pdf",
        shrink_pdf="results/gap/gap_shrink.pdf",
        explanation_pdf="results/gap/gap_explanation.pdf",
    params:
        code=CODE_DIGEST,
        place=config["gap"].get("place"),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_figures.log",
    script:
        "../scripts/gap_figures.py"


rule gap_benchmark_item:
    """One blind-benchmark item: rig records with a hidden effect, the chain's identification and the gap diagnosis, scored against the hidden truth."""
    input:
        unpack(benchmark_floor_input),
    output:
        item="results/gap_benchmark/items/{item}.json",
        diagnosis="results/gap_benchmark/items/{item}/diagnosis.json",
        dataset="results/gap_benchmark/items/{item}/gap.nc",
    params:
        code=CODE_DIGEST,
        spec=lambda wc: {**benchmark_items(), **ladder_items()}[wc.item],
        config=benchmark_base_config(),
    wildcard_constraints:
        item=r"[a-z_]+-[0-9]+-s[0-9]+",
    threads: 1
    # the long items first (longest-processing-time order): none is left to run alone at the end
    priority: lambda wc: benchmark_item_priority(wc.item)
    resources:
        runtime=20,
        mem_mb=2000,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_benchmark/{item}.log",
    script:
        "../scripts/gap_benchmark_item.py"


rule gap_benchmark_item_figures:
    """One benchmark item's gap figures and report section, drawn from its diagnosis as `snakemake gap` draws the configured data's."""
    input:
        diagnosis="results/gap_benchmark/items/{item}/diagnosis.json",
        dataset="results/gap_benchmark/items/{item}/gap.nc",
    output:
        **{v: f"results/gap_benchmark/items/{{item}}/gap_{v}.png" for v in GAP_VIEWS},
        tex="results/gap_benchmark/items/{item}/gap.tex",
    params:
        code=CODE_DIGEST,
        place=config["gap"].get("place"),
    wildcard_constraints:
        item=r"[a-z_]+-[0-9]+-s[0-9]+",
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/gap_benchmark/{item}_figures.log",
    script:
        "../scripts/gap_benchmark_item_figures.py"


rule gap_benchmark_figures:
    """Target: every blind-benchmark item's gap figures and report section (results/gap_benchmark/items/ITEM/)."""
    input:
        expand("results/gap_benchmark/items/{item}/gap.tex", item=list(benchmark_items())),


rule gap_ladder_figures:
    """Target: every detection-ladder item's gap figures and report section (results/gap_benchmark/items/ITEM/)."""
    input:
        expand("results/gap_benchmark/items/{item}/gap.tex", item=list(ladder_items())),


rule gap_benchmark:
    """The blind benchmark's summary: top-1 accuracy, false alarms and confusion over every item (results/gap_benchmark/benchmark.json)."""
    input:
        rows=expand("results/gap_benchmark/items/{item}.json", item=list(benchmark_items())),
    output:
        summary="results/gap_benchmark/benchmark.json",
        confusion=report(
            "results/gap_benchmark/confusion.csv", caption="../report/gap_benchmark.rst", category="Gap diagnosis"
        ),
        figure=report(
            "results/gap_benchmark/confusion.png", caption="../report/gap_benchmark.rst", category="Gap diagnosis"
        ),
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
        unpack(benchmark_floor_input),
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
    """The report's gap section in LaTeX (results/report/gap.tex)."""
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


rule record_checks:
    """The load cases' records against each other (accelerance at the drive) and against the identified model's prediction at each record's measured force: a units factor, a flipped sign, a swapped channel or a gross disagreement, named with its fix (results/gap/record_checks.json)."""
    priority: CRITICAL_PATH
    input:
        modes="results/linear/linear_modes.nc",
        modal="results/linear/modal.nc",
        fit="results/friction/friction_fit.nc",
        raw=[raw_record(c) for c in load_cases()],
        checks=[f"results/{c}/raw_check.nc" for c in load_cases()],
    output:
        "results/gap/record_checks.json",
    params:
        code=CODE_DIGEST,
        records=records_digest([raw_record(c) for c in load_cases()]),
        structure=config["structure"],
        thresholds=config["gap"]["record_checks"],
        n_harmonics=config["nonlinear"]["n_harmonics"],
        calibration_case=calibration_case(),
        cases=load_cases(),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/record_checks.log",
    script:
        "../scripts/record_checks.py"
