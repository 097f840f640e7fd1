# The virtual test rig: raw signals a real rig would record, truth kept apart.


rule rig:
    input:
        rig_outputs(),


rule rig_random_test:
    output:
        raw="data/raw/random_test.nc",
        truth="data/truth/random_test.nc",
    params:
        seed=config["seed"],
        structure=config["structure"],
        rig=config.get("rig", {}),
        random_test=config.get("random_test", {}),
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/rig_random_test.log",
    benchmark:
        "benchmarks/rules/rig_random_test.tsv"
    script:
        "../scripts/rig_random_test.py"
