# The dual-sine records of the load cases (Sections 3-5): checks, and later the nonlinear chain.


rule raw_check:
    """Reads and checks one load case's dual-sine record (periods, clipping, frequency, stationarity) and its harmonic content."""
    priority: CRITICAL_PATH
    input:
        raw=lambda wc: raw_record(wc.case),
        frf="results/linear/frf.nc",
    output:
        check="results/{case}/raw_check.nc",
    params:
        code=CODE_DIGEST,
        records=lambda wc: records_digest(raw_record(wc.case)),
        structure=config["structure"],
        checks=config["raw_checks"],
        n_harmonics=config["nonlinear"]["n_harmonics"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/raw_check_{case}.log",
    script:
        "../scripts/raw_check.py"


rule generalized_coordinates:
    """The generalized coordinates of one load case from its accelerations (Eqs. 15-17; Fig. 4)."""
    priority: CRITICAL_PATH
    input:
        raw=lambda wc: raw_record(wc.case),
        check="results/{case}/raw_check.nc",
        modes="results/linear/linear_modes.nc",
    output:
        gc="results/{case}/generalized_coordinates.nc",
    params:
        code=CODE_DIGEST,
        records=lambda wc: records_digest(raw_record(wc.case)),
        nonlinear=config["nonlinear"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/generalized_coordinates_{case}.log",
    script:
        "../scripts/generalized_coordinates.py"


rule nonlinear_modes:
    """One load case's nonlinear normal modes (Eq. 20) and their phase check (Section 4)."""
    priority: CRITICAL_PATH
    input:
        raw=lambda wc: raw_record(wc.case),
        gc="results/{case}/generalized_coordinates.nc",
        modes="results/linear/linear_modes.nc",
    output:
        nnm="results/{case}/nonlinear_modes.nc",
    params:
        code=CODE_DIGEST,
        records=lambda wc: records_digest(raw_record(wc.case)),
        structure=config["structure"],
        nonlinear=config["nonlinear"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/nonlinear_modes_{case}.log",
    script:
        "../scripts/nonlinear_modes.py"


rule reduced_model:
    """One load case's Galerkin reduced model (Eqs. 11-12; Fig. 5's reconstruction)."""
    priority: CRITICAL_PATH
    input:
        raw=lambda wc: raw_record(wc.case),
        nnm="results/{case}/nonlinear_modes.nc",
        modes="results/linear/linear_modes.nc",
    output:
        reduced="results/{case}/reduced_model.nc",
    params:
        code=CODE_DIGEST,
        records=lambda wc: records_digest(raw_record(wc.case)),
        structure=config["structure"],
        nonlinear=config["nonlinear"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/reduced_model_{case}.log",
    script:
        "../scripts/reduced_model.py"


rule contact_forces:
    """One load case's contact forces S(t) and N(t) by force-state mapping, by the working method and the paper's chain (Fig. 6)."""
    priority: CRITICAL_PATH
    input:
        unpack(contact_forces_inputs),
    output:
        forces="results/{case}/contact_forces.nc",
    params:
        code=CODE_DIGEST,
        records=lambda wc: records_digest(raw_record(wc.case)),
        structure=config["structure"],
        nonlinear=config["nonlinear"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/contact_forces_{case}.log",
    benchmark:
        "benchmarks/rules/contact_forces_{case}.tsv"
    script:
        "../scripts/contact_forces.py"


rule harmonic_study:
    """How the identified contact forces and the friction fit move with the number of harmonics K (results/studies/harmonic_count.csv)."""
    input:
        raw=lambda wc: raw_record(calibration_case()),
        truth=lambda wc: f"data/truth/{calibration_case()}.nc",
        modes="results/linear/linear_modes.nc",
        modal="results/linear/modal.nc",
    output:
        table=report("results/studies/harmonic_count.csv", caption="../report/harmonic_study.rst", category="Studies"),
    params:
        code=CODE_DIGEST,
        records=records_digest(raw_record(calibration_case())),
        structure=config["structure"],
        counts=config["nonlinear"]["harmonic_study"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/harmonic_study.log",
    script:
        "../scripts/harmonic_study.py"
