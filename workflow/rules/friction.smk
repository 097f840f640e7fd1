# The modified Valanis law fitted on the calibration case, and validated on every load case (Section 5).


rule test_damping:
    """The driven mode's damping at test level: the random test's ratio times the factor where the friction law fitted to the calibration record's contact forces misfits least, applied where the other load cases confirm it (contactid.test_damping)."""
    priority: CRITICAL_PATH
    input:
        raw=[raw_record(c) for c in load_cases()],
        modes="results/linear/linear_modes.nc",
        modal="results/linear/modal.nc",
    output:
        damping="results/friction/test_damping.nc",
    params:
        code=CODE_DIGEST,
        records=lambda wc: records_digest([raw_record(c) for c in load_cases()]),
        structure=config["structure"],
        # the law's fit settings without friction.confidence (the profile's interval is at the default 95 %): a
        # changed confidence reruns the friction fit and what follows it, not the contact forces
        friction={k: v for k, v in config["friction"].items() if k != "confidence"},
        seed=config["seed"],
        nonlinear=config["nonlinear"],
        # the held-out records' test reads these gap settings alone: another candidate list does not rerun the chain
        gap=records_test_gap_config(),
        cases=load_cases(),
        calibration_case=calibration_case(),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/test_damping.log",
    benchmark:
        "benchmarks/rules/test_damping.tsv"
    script:
        "../scripts/test_damping.py"


rule friction_fit:
    """The modified Valanis law (Eqs. 21-22) fitted by a genetic algorithm and a polish to S(t) of the calibration case, with profile-likelihood intervals (Table 4)."""
    priority: CRITICAL_PATH
    input:
        forces=lambda wc: f"results/{calibration_case()}/contact_forces.nc",
    output:
        fit="results/friction/friction_fit.nc",
    params:
        code=CODE_DIGEST,
        friction=config["friction"],
        preload=config["structure"]["preload_n"],
        seed=config["seed"],
        n_harmonics=config["nonlinear"]["n_harmonics"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/friction_fit.log",
    benchmark:
        "benchmarks/rules/friction_fit.tsv"
    script:
        "../scripts/friction_fit.py"


rule validate:
    """The fitted friction law predicting one load case's S(t) from its identified motion and N(t) (Fig. 9)."""
    priority: CRITICAL_PATH
    input:
        unpack(validate_inputs),
    output:
        validation="results/{case}/validation.nc",
    params:
        code=CODE_DIGEST,
        preload=config["structure"]["preload_n"],
        n_harmonics=config["nonlinear"]["n_harmonics"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/validate_{case}.log",
    script:
        "../scripts/validate.py"
