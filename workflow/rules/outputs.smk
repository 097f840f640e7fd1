# Outputs for people: tables, figures and the headline numbers.


rule paper_consistency:
    """The paper's Tables 1 and 3 against a faithful model of the test structure: where the paper's own numbers disagree."""
    output:
        table=report(
            "results/tables/paper_consistency.csv",
            caption="../report/paper_consistency.rst",
            category="Tables",
        ),
    params:
        code=CODE_DIGEST,
        structure=config["structure"],
        truth=config["rig"].get("truth", {}),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/paper_consistency.log",
    benchmark:
        "benchmarks/rules/paper_consistency.tsv"
    script:
        "../scripts/paper_consistency.py"


rule linear_tables:
    """Tables 1-3: measured (identified), model and paper frequencies and the stiction stiffnesses (results/tables/)."""
    input:
        modal="results/linear/modal.nc",
        stiction="results/linear/stiction.nc",
        truth=random_test_truth(),
    output:
        table1=report("results/tables/table1.csv", caption="../report/table1.rst", category="Tables"),
        table3=report("results/tables/table3.csv", caption="../report/table3.rst", category="Tables"),
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/linear_tables.log",
    script:
        "../scripts/linear_tables.py"


rule fig03_frf:
    """Fig. 3: every sensor's FRF, measured and synthesised from the identified modes, phase, coherence (results/figures/fig03_frf.png)."""
    input:
        frf="results/linear/frf.nc",
        modal="results/linear/modal.nc",
    output:
        png=report("results/figures/fig03_frf.png", caption="../report/fig03.rst", category="Figures"),
        pdf="results/figures/fig03_frf.pdf",
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/fig03_frf.log",
    script:
        "../scripts/fig03_frf.py"


rule stability_diagram:
    """The stability diagram of the modal fit: LSCF poles over model order, the chosen poles ringed, on the summed FRF (results/figures/stability.png)."""
    input:
        frf="results/linear/frf.nc",
        modal="results/linear/modal.nc",
    output:
        png=report("results/figures/stability.png", caption="../report/stability.rst", category="Figures"),
        pdf="results/figures/stability.pdf",
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/stability_diagram.log",
    script:
        "../scripts/stability_diagram.py"


rule summary:
    """Every identified number, its interval and, on rig data, its truth in one file (results/summary.json)."""
    input:
        unpack(summary_inputs),
    output:
        summary="results/summary.json",
    params:
        code=CODE_DIGEST,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/summary.log",
    script:
        "../scripts/summary.py"


rule fig04_generalized_coordinates:
    """Fig. 4: the generalized coordinates of the figure case."""
    input:
        gc=lambda wc: f"results/{figure_case()}/generalized_coordinates.nc",
    output:
        png=report(
            "results/figures/fig04_generalized_coordinates.png", caption="../report/fig04.rst", category="Figures"
        ),
        pdf="results/figures/fig04_generalized_coordinates.pdf",
    params:
        code=CODE_DIGEST,
        case=figure_case() if load_cases() else None,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/fig04.log",
    script:
        "../scripts/fig04.py"


rule fig05_reconstruction:
    """Fig. 5: the measured accelerations against the reduced model's reconstruction."""
    input:
        nnm=lambda wc: f"results/{figure_case()}/nonlinear_modes.nc",
    output:
        png=report("results/figures/fig05_reconstruction.png", caption="../report/fig05.rst", category="Figures"),
        pdf="results/figures/fig05_reconstruction.pdf",
    params:
        code=CODE_DIGEST,
        case=figure_case() if load_cases() else None,
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/fig05.log",
    script:
        "../scripts/fig05.py"


rule fig06_contact_forces:
    """Fig. 6: the identified contact forces and hysteresis loops of every load case."""
    input:
        forces=expand("results/{case}/contact_forces.nc", case=load_cases()),
    output:
        png=report("results/figures/fig06_contact_forces.png", caption="../report/fig06.rst", category="Figures"),
        pdf="results/figures/fig06_contact_forces.pdf",
    params:
        code=CODE_DIGEST,
        cases=load_cases(),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/fig06.log",
    script:
        "../scripts/fig06.py"


rule friction_outputs:
    """Table 4 and Figs. 7-9: the fitted friction law, its intervals and the validation on every load case."""
    priority: CRITICAL_PATH
    input:
        fit="results/friction/friction_fit.nc",
        validations=expand("results/{case}/validation.nc", case=load_cases()),
    output:
        table4=report("results/tables/table4.csv", caption="../report/table4.rst", category="Tables"),
        fig07_png=report("results/figures/fig07_e0.png", caption="../report/fig07.rst", category="Figures"),
        fig07_pdf="results/figures/fig07_e0.pdf",
        fig08_png=report("results/figures/fig08_s_xi.png", caption="../report/fig08.rst", category="Figures"),
        fig08_pdf="results/figures/fig08_s_xi.pdf",
        fig09_png=report("results/figures/fig09_s_xidot.png", caption="../report/fig09.rst", category="Figures"),
        fig09_pdf="results/figures/fig09_s_xidot.pdf",
        convergence_png=report(
            "results/figures/friction_convergence.png", caption="../report/convergence.rst", category="Figures"
        ),
    params:
        code=CODE_DIGEST,
        cases=load_cases(),
        truth_friction=(
            None
            if _is_measured(config["load_cases"].get(calibration_case()))
            else config["rig"].get("truth", {}).get("friction")
        ),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/friction_outputs.log",
    script:
        "../scripts/friction_outputs.py"
