# The reproduction report: generated fragments, then LaTeX to PDF.


rule report_fragments:
    """The numbers and tables the PDF prints, as LaTeX fragments (results/report/numbers.tex and tables)."""
    input:
        summary="results/summary.json",
        table1="results/tables/table1.csv",
        table3="results/tables/table3.csv",
        table4="results/tables/table4.csv",
        consistency="results/tables/paper_consistency.csv",
        intervals="results/gap/friction_intervals.json",
        updated_model="results/gap/updated_model.json",
    output:
        numbers="results/report/numbers.tex",
        setup="results/report/setup.tex",
        table1="results/report/table1.tex",
        table3="results/report/table3.tex",
        table4="results/report/table4.tex",
        consistency="results/report/consistency.tex",
        contact="results/report/contact.tex",
        datachecks="results/report/datachecks.tex",
        alerts="results/report/alerts.tex",
    params:
        code=CODE_DIGEST,
        structure=config["structure"],
        calibration_case=config["nonlinear"]["calibration_case"],
        figure_case=figure_case() if load_cases() else None,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/report_fragments.log",
    script:
        "../scripts/report_fragments.py"


rule report:
    """The PDF report compiled with latexmk from paper/report.tex and the fragments (results/report/report.pdf)."""
    input:
        tex="paper/report.tex",
        fragments=rules.report_fragments.output,
        gap="results/report/gap.tex",
        noise="results/report/noise.tex",
        noise_figure=["results/figures/noise_study.pdf"] if noise_study_in_report() else [],
        gap_figures=[f"results/gap/gap_{v}.pdf" for v in ("stages", "ranking", "shrink", "explanation")],
        benchmark_figure=(["results/gap_benchmark/confusion.png"] if gap_benchmark_in_report() else []),
        figures=expand(
            "results/figures/{fig}.pdf",
            fig=[
                "fig03_frf",
                "stability",
                "fig04_generalized_coordinates",
                "fig05_reconstruction",
                "fig06_contact_forces",
                "fig07_e0",
                "fig08_s_xi",
                "fig09_s_xidot",
            ],
        ),
    output:
        pdf="results/report/report.pdf",
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/report.log",
    script:
        "../scripts/report.py"
