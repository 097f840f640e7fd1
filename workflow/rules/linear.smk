# The linear chain (Sections 3-4): FRF, modal fit, stiction stiffness, linear modes.


# The FRFs come from the random test's time record (rule frf), or, with random_test.format: uff58_frf, from a
# file of measured FRFs (rule import_uff58_frf); either writes results/linear/frf.nc, so everything after is the
# same. The measured and the synthesised FRFs go back out as universal files (frf_measured_uff, frf_synthesised_uff).
if random_test_is_frf_file():

    rule import_uff58_frf:
        """Measured FRFs (UFF58 function type 4, accelerance, with coherence where given) of every sensor, checked (even lines covering modal.band_hz, resolution, coherence) as the FRF dataset (results/linear/frf.nc)."""
        priority: CRITICAL_PATH + 2
        input:
            file=config["random_test"]["file"],
        output:
            frf="results/linear/frf.nc",
        params:
            code=CODE_DIGEST,
            records=records_digest(config["random_test"]["file"]),
            block=config["random_test"],
            structure=config["structure"],
            band_hz=config["modal"]["band_hz"],
            checks=config["raw_checks"],
        conda:
            "../envs/contactid.yaml"
        log:
            "logs/frf.log",
        benchmark:
            "benchmarks/rules/frf.tsv"
        script:
            "../scripts/import_frf.py"

else:

    rule frf:
        """H1 frequency response functions and coherence of every sensor from the random test (results/linear/frf.nc)."""
        priority: CRITICAL_PATH + 2
        input:
            raw=random_test_raw(),
        output:
            frf="results/linear/frf.nc",
        params:
            code=CODE_DIGEST,
            records=records_digest(random_test_raw()),
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
        random_test=config["random_test"],
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


rule frf_measured_uff:
    """The measured H1 FRFs with their coherence, every sensor, as UFF58 datasets of function types 4 and 6 for other modal tools (results/linear/frf_measured.uff)."""
    input:
        frf="results/linear/frf.nc",
    output:
        uff="results/linear/frf_measured.uff",
    params:
        code=CODE_DIGEST,
        kind="measured",
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/frf_measured_uff.log",
    script:
        "../scripts/frf_uff.py"


rule frf_synthesised_uff:
    """The FRFs the identified modes synthesise (LSFD residues and residual terms fitted in modal.band_hz), every sensor, on the measured lines, as UFF58 datasets of function type 4 (results/linear/frf_synthesised.uff)."""
    input:
        frf="results/linear/frf.nc",
        modal="results/linear/modal.nc",
    output:
        uff="results/linear/frf_synthesised.uff",
    params:
        code=CODE_DIGEST,
        kind="synthesised",
    conda:
        "../envs/contactid.yaml"
    log:
        "logs/frf_synthesised_uff.log",
    script:
        "../scripts/frf_uff.py"
