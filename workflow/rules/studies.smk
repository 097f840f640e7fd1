# Parameter studies as Snakemake jobs: one small, independent job per point of a parameter table
# (snakemake.utils.Paramspace), with declared resources, and a gathering rule. Run them on one
# machine or through a cluster executor (profiles/default, profiles/slurm; docs/studies.md, "Running on a cluster").


rule noise_study_point:
    """One point of the noise and record-length study: rig records, identification and the errors against the truth."""
    output:
        point=f"results/studies/noise/{NOISE_SPACE.wildcard_pattern}.json",
    params:
        code=CODE_DIGEST,
        point=NOISE_SPACE.instance,
        config=study_base_config(),
    threads: 1
    resources:
        runtime=15,
        mem_mb=2000,
    conda:
        "../envs/contactid.yaml"
    log:
        f"logs/noise_study/{NOISE_SPACE.wildcard_pattern}.log",
    script:
        "../scripts/noise_study_point.py"


rule noise_study:
    """The noise and record-length study gathered: errors of mu, e_0 and k_t over the points (results/studies/noise_study.nc, figure)."""
    input:
        points=expand("results/studies/noise/{params}.json", params=NOISE_SPACE.instance_patterns),
    output:
        dataset="results/studies/noise_study.nc",
        table="results/studies/noise_study.csv",
        png="results/figures/noise_study.png",
        pdf="results/figures/noise_study.pdf",
    params:
        code=CODE_DIGEST,
        default_noise=config["rig"]["noise_fraction"],
    resources:
        runtime=5,
        mem_mb=1000,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/noise_study.log",
    script:
        "../scripts/noise_study.py"


rule noise_report_fragment:
    """The report's noise-study section in LaTeX (results/report/noise.tex; empty unless noise_study.in_report)."""
    input:
        unpack(noise_report_inputs),
    output:
        tex="results/report/noise.tex",
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/noise_report_fragment.log",
    script:
        "../scripts/noise_report_fragment.py"
