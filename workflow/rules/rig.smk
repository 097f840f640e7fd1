# The virtual test rig: raw signals a real rig would record, truth kept apart.


rule rig:
    """Target: the virtual rig's raw records (data/raw/) and their truth (data/truth/) for every configured record."""
    input:
        rig_outputs(),


rule rig_random_test:
    """The virtual rig's random test: force and accelerations with noise (data/raw/random_test.nc) and its truth."""
    priority: CRITICAL_PATH + 2
    output:
        raw="data/raw/random_test.nc",
        truth="data/truth/random_test.nc",
    params:
        code=CODE_DIGEST,
        seed=config["seed"],
        structure=config["structure"],
        rig=random_test_rig_config(config["rig"]),
        random_test=config["random_test"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/rig_random_test.log",
    benchmark:
        "benchmarks/rules/rig_random_test.tsv"
    script:
        "../scripts/rig_random_test.py"


rule rig_dual_sine:
    """The virtual rig's response-controlled dual-sine test of one load case (data/raw/{case}.nc) and its truth."""
    priority: CRITICAL_PATH
    output:
        raw="data/raw/{case}.nc",
        truth="data/truth/{case}.nc",
    wildcard_constraints:
        case=rig_case_pattern(),
    params:
        code=CODE_DIGEST,
        seed=config["seed"],
        structure=config["structure"],
        rig=config["rig"],
        case_cfg=lambda wc: config["load_cases"][wc.case],
        sampling_rate_hz=config["random_test"]["sampling_rate_hz"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/rig_dual_sine_{case}.log",
    benchmark:
        "benchmarks/rules/rig_dual_sine_{case}.tsv"
    script:
        "../scripts/rig_dual_sine.py"
