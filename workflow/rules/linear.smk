# The linear chain (Sections 3-4): FRF, modal fit, stiction stiffness, linear modes.


rule frf:
    """H1 frequency response functions and coherence of every sensor from the random test (results/linear/frf.nc)."""
    priority: CRITICAL_PATH + 2
    input:
        raw=random_test_raw(),
    output:
        frf="results/linear/frf.nc",
    params:
        code=CODE_DIGEST,
        frf=config["frf"],
        structure=config["structure"],
        blocks=config["modal"]["uncertainty_blocks"],
        band_hz=config["modal"]["band_hz"],
        checks=config["raw_checks"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/frf.log",
    benchmark:
        "benchmarks/rules/frf.tsv"
    script:
        "../scripts/frf.py"


rule modal:
    """Natural frequencies, damping and mode shapes by LSCF/LSFD on the FRFs, with their uncertainty (results/linear/modal.nc; Table 1)."""
    priority: CRITICAL_PATH + 2
    input:
        frf="results/linear/frf.nc",
    output:
        modal="results/linear/modal.nc",
    params:
        code=CODE_DIGEST,
        modal=config["modal"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/modal.log",
    benchmark:
        "benchmarks/rules/modal.tsv"
    script:
        "../scripts/modal.py"


rule stiction_stiffness:
    """The contact stiffnesses at stiction k_t and k_n fitted to the natural frequencies, with the intervals the data allow (results/linear/stiction.nc; Table 3)."""
    priority: CRITICAL_PATH + 2
    input:
        modal="results/linear/modal.nc",
    output:
        stiction="results/linear/stiction.nc",
    params:
        code=CODE_DIGEST,
        structure=config["structure"],
        stiction=config["stiction"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/stiction_stiffness.log",
    benchmark:
        "benchmarks/rules/stiction_stiffness.tsv"
    script:
        "../scripts/stiction_stiffness.py"


rule linear_modes:
    """The stuck structure's linear modes on a grid (Eqs. 15-17's basis; results/linear/linear_modes.nc)."""
    priority: CRITICAL_PATH + 2
    input:
        stiction="results/linear/stiction.nc",
    output:
        modes="results/linear/linear_modes.nc",
    params:
        code=CODE_DIGEST,
        structure=config["structure"],
        linear_modes=config["linear_modes"],
        k_n_prior=config["stiction"]["k_n_prior_n_per_m"],
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/linear_modes.log",
    benchmark:
        "benchmarks/rules/linear_modes.tsv"
    script:
        "../scripts/linear_modes.py"
