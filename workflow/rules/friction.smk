# The modified Valanis law fitted on the calibration case, and validated on every load case (Section 5).


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
