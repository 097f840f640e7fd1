# Shared helpers: config checks and path functions, so that rules stay declarative.

from snakemake.utils import Paramspace

from contactid.config import check_config
from contactid.measured_files import measured_digests, measured_records, record_files
from contactid.studies import noise_study_table
from contactid.rig.structure import random_test_rig_config

# the schema's cross-field checks, and the measured files: a path that does not exist (or two records on one file)
# stops the run here, before any job, naming the config key
check_config(config, "config (" + " over ".join(map(str, workflow.configfiles)) + ")")

# every measured file (and CSV sidecar) the config names: the rules that read one take its sha256 as a parameter
# (records_digest), so that a record replaced by another, whatever its modification time, reruns what it fed
MEASURED_FILES = {path for _, block in measured_records(config) for _, path in record_files(block)}


def records_digest(paths):
    """{path: sha256} of the measured files among ``paths`` (one or a list; the rig's and imported records are
    tracked by their own rules): a parameter of each rule that reads a measured file."""
    return measured_digests(paths, MEASURED_FILES, os.path.join(".snakemake", "contactid", "measured-digests.json"))


# The chain from the raw records to the gap diagnosis is the workflow's critical path: its jobs go first
# whenever a core is free (the linear chain, which everything waits for, before the dual-sine rigs), and the
# figures and tables fill the cores around them. Before, the scheduler ran two dual-sine rigs first and the FRF
# waited 13 s for a core; with the linear chain alone first, the last rig ran after the diagnosis. The friction law's
# outputs (its validations, intervals, Table 4 and Figs. 7-9) are among the report's last inputs: without a priority
# the validations waited 15-25 s behind the figures after the fit (default workflow 92-96 s, with it 88-91 s).
CRITICAL_PATH = 10


def _is_measured(block):
    return (block or {}).get("source", "rig") == "measured"


def _import_format(block):
    """The importer a measured record needs (uff58, tdms, csv), or None (rig, a raw netCDF file, or measured FRFs:
    rule import_uff58_frf writes results/linear/frf.nc itself)."""
    fmt = (block or {}).get("format", "netcdf")
    return fmt if _is_measured(block) and fmt not in ("netcdf", "uff58_frf") else None


def random_test_is_frf_file():
    """Is the random test given as measured FRFs (random_test.format: uff58_frf) instead of a time record?"""
    rt = config["random_test"]
    return _is_measured(rt) and rt.get("format") == "uff58_frf"


def record_block(record):
    """The config block of a record: a load case, or the random test."""
    return config["random_test"] if record == "random_test" else config["load_cases"][record]


def imported_records(fmt):
    """Records (load cases, random_test) that the importer of ``fmt`` converts."""
    names = ["random_test"] + list(config.get("load_cases") or {})
    return [r for r in names if _import_format(record_block(r)) == fmt]


def import_pattern(fmt):
    """Wildcard constraint matching exactly the records imported from ``fmt`` (or nothing)."""
    return "|".join(imported_records(fmt)) or "(?!)"


def import_inputs(wildcards):
    """The measured file, and for CSV its sidecar YAML."""
    from contactid.importers import sidecar_path

    block = record_block(wildcards.record)
    inputs = {"file": block["file"]}
    if block.get("format") == "csv":
        inputs["sidecar"] = sidecar_path(block["file"], block.get("sidecar"))
    return inputs


def _measured_path(record):
    block = record_block(record)
    return f"data/imported/{record}.nc" if _import_format(block) else block["file"]


def load_cases():
    """Names of every configured load case."""
    return sorted(config.get("load_cases") or {}, key=lambda c: int(c[2:]))


def rig_cases():
    """Load cases whose raw record the rig produces."""
    return [c for c in load_cases() if not _is_measured(config["load_cases"][c])]


def rig_case_pattern():
    """Wildcard constraint matching exactly the rig's load cases (or nothing)."""
    return "|".join(rig_cases()) or "(?!)"


def random_test_raw():
    """The random-test record: the rig's output or the user's measured file."""
    rt = config["random_test"]
    return _measured_path("random_test") if _is_measured(rt) else "data/raw/random_test.nc"


def random_test_truth():
    """Truth of the random test, only where the rig produced it."""
    return [] if _is_measured(config.get("random_test")) else "data/truth/random_test.nc"


def raw_record(case):
    """The dual-sine record of a load case: the rig's output or the user's measured file."""
    lc = config["load_cases"][case]
    return _measured_path(case) if _is_measured(lc) else f"data/raw/{case}.nc"


def truth_records():
    """Truth of every rig load case, by case."""
    return {c: f"data/truth/{c}.nc" for c in rig_cases()}


def rig_outputs():
    """Every raw record the config asks the rig to produce."""
    out = [] if _is_measured(config.get("random_test")) else ["data/raw/random_test.nc"]
    return out + [f"data/raw/{c}.nc" for c in rig_cases()]


def calibration_case():
    """The load case the friction law is fitted on (and the harmonic study uses)."""
    return config["nonlinear"]["calibration_case"]


def figure_case():
    """The load case of Figs. 4 and 5 (the paper shows its largest, load case 3)."""
    return config["nonlinear"].get("figure_case") or load_cases()[-1]


def contact_forces_inputs(wildcards):
    inputs = {
        "raw": raw_record(wildcards.case),
        "reduced": f"results/{wildcards.case}/reduced_model.nc",
        "modes": "results/linear/linear_modes.nc",
        "modal": "results/linear/modal.nc",
        "stiction": "results/linear/stiction.nc",
        "updating": "results/gap/model_updating.json",
    }
    if wildcards.case in rig_cases():
        inputs["truth"] = f"data/truth/{wildcards.case}.nc"
    return inputs


def validate_inputs(wildcards):
    inputs = {"forces": f"results/{wildcards.case}/contact_forces.nc", "fit": "results/friction/friction_fit.nc"}
    if wildcards.case in rig_cases():
        inputs["truth"] = f"data/truth/{wildcards.case}.nc"
    return inputs


def summary_inputs(wildcards):
    """Everything the headline numbers are read from, named for the summary script."""
    inputs = {
        "modal": "results/linear/modal.nc",
        "stiction": "results/linear/stiction.nc",
        "frf": "results/linear/frf.nc",
    }
    if not _is_measured(config.get("random_test")):
        inputs["truth"] = "data/truth/random_test.nc"
    for c in load_cases():
        inputs[f"check_{c}"] = f"results/{c}/raw_check.nc"
        inputs[f"forces_{c}"] = f"results/{c}/contact_forces.nc"
        inputs[f"nnm_{c}"] = f"results/{c}/nonlinear_modes.nc"
        inputs[f"validation_{c}"] = f"results/{c}/validation.nc"
    if load_cases():
        inputs["fit"] = "results/friction/friction_fit.nc"
        inputs["test_damping"] = "results/friction/test_damping.nc"
        inputs["friction_intervals"] = "results/gap/friction_intervals.json"
        inputs["record_checks"] = "results/gap/record_checks.json"
    for c, path in truth_records().items():
        inputs[f"truth_{c}"] = path
    return inputs


def all_outputs():
    return [
        "results/linear/linear_modes.nc",
        "results/tables/table1.csv",
        "results/tables/table3.csv",
        "results/tables/paper_consistency.csv",
        "results/figures/fig03_frf.png",
        "results/figures/fig03_frf.pdf",
        "results/linear/frf_measured.uff",
        "results/linear/frf_synthesised.uff",
        "results/figures/stability.png",
        "results/figures/stability.pdf",
        *[f"results/{c}/raw_check.nc" for c in load_cases()],
        *[f"results/{c}/contact_forces.nc" for c in load_cases()],
        *[f"results/{c}/validation.nc" for c in load_cases()],
        *(
            [
                "results/tables/table4.csv",
                "results/figures/fig07_e0.png",
                "results/figures/fig08_s_xi.png",
                "results/figures/fig09_s_xidot.png",
                "results/figures/friction_convergence.png",
            ]
            if load_cases()
            else []
        ),
        *(["results/studies/harmonic_count.csv"] if calibration_case() in rig_cases() else []),
        *(
            [
                "results/figures/fig04_generalized_coordinates.png",
                "results/figures/fig05_reconstruction.png",
                "results/figures/fig06_contact_forces.png",
            ]
            if load_cases()
            else []
        ),
        "results/summary.json",
        *(gap_outputs() if load_cases() else []),
        *(["results/studies/noise_study.nc", "results/figures/noise_study.png"] if noise_study_in_report() else []),
        *(["results/report/report.pdf"] if load_cases() else []),
    ]


def gap_inputs(wildcards):
    """The diagnosis reads the raw records of every load case and the chain's identified model."""
    inputs = {
        "modes": "results/linear/linear_modes.nc",
        "modal": "results/linear/modal.nc",
        "frf": "results/linear/frf.nc",
        "fit": "results/friction/friction_fit.nc",
        "updating": "results/gap/model_updating.json",
    }
    inputs["raw"] = [raw_record(c) for c in load_cases()]
    inputs.update(gap_floor_input())
    inputs["checks"] = [
        f"results/{c}/raw_check.nc" for c in load_cases()
    ]  # a record that fails validation stops the gap
    return inputs


# the gap diagnosis's figures (contactid.gap.figures: IN_REPORT + DIAGNOSTIC), one PNG each
GAP_VIEWS = ("stages", "harmonics", "cycle", "force_state", "ranking", "shrink", "explanation")


def gap_outputs():
    return [
        "results/gap/diagnosis.json",
        "results/gap/gap.nc",
        "results/gap/updated_model.json",
        "results/gap/friction_intervals.json",
    ] + [f"results/gap/gap_{v}.png" for v in GAP_VIEWS]


def measured_floor():
    """Whether gap.min_gap is measured (gap.measure_floor: rule gap_floor) rather than given."""
    return bool(config["gap"].get("measure_floor", True))


def gap_floor_input(wildcards=None):
    """The measured floor of the held-out gap where gap.measure_floor (results/gap/floor.json), else nothing."""
    return {"floor": "results/gap/floor.json"} if measured_floor() else {}


# the gap settings the held-out records' test of a base-model change reads (contactid.gap.evidence.records_test_of_update)
RECORDS_TEST_GAP_KEYS = (
    "n_harmonics",
    "candidates",
    "min_reduction",
    "noise_factor",
    "n_bootstrap",
    "max_evaluations",
    "place",
)


def records_test_gap_config():
    """The gap block's keys the held-out records' test reads (``RECORDS_TEST_GAP_KEYS``), as configured."""
    return {k: config["gap"][k] for k in RECORDS_TEST_GAP_KEYS if k in config["gap"]}


def benchmark_floor_input(wildcards=None):
    """The blind benchmark's measured floor where gap.measure_floor (results/gap_benchmark/floor.json)."""
    return {"floor": "results/gap_benchmark/floor.json"} if measured_floor() else {}


def benchmark_base_config():
    """What a benchmark item depends on: the config without the benchmark's own block."""
    return {k: v for k, v in config.items() if k != "gap_benchmark"}


def benchmark_items():
    """{item name: spec} of the blind gap benchmark (see config/README.md, gap_benchmark)."""
    from contactid.gap.bench_items import benchmark_items as items

    return items(config["gap_benchmark"], int(config["seed"]))


def ladder_items():
    """{item name: spec} of the detection ladder (gap_benchmark.ladder; `snakemake gap_ladder`)."""
    from contactid.gap.bench_items import ladder_items as items

    return items(config["gap_benchmark"], int(config["seed"]))


def benchmark_item_priority(item):
    """A benchmark or ladder item's scheduling priority: its expected run time in seconds
    (contactid.gap.bench_items.expected_seconds), so that the long items start first."""
    from contactid.gap.bench_items import expected_seconds

    return expected_seconds({**benchmark_items(), **ladder_items()}[item])


def gap_report_inputs(wildcards):
    """The report's gap section: the diagnosis, and the blind benchmark when gap_benchmark.in_report."""
    inputs = {"diagnosis": "results/gap/diagnosis.json", "intervals": "results/gap/friction_intervals.json"}
    if gap_benchmark_in_report():
        inputs["benchmark"] = "results/gap_benchmark/benchmark.json"
    return inputs


# ---- parameter studies (workflow/rules/studies.smk) ----

NOISE_SPACE = Paramspace(noise_study_table(config.get("noise_study")), filename_params="*", param_sep="~")


def study_base_config():
    """What a study point depends on: the rig, the structure and the identification settings."""
    keys = (
        "seed",
        "structure",
        "random_test",
        "rig",
        "frf",
        "modal",
        "stiction",
        "linear_modes",
        "nonlinear",
        "friction",
        "load_cases",
    )
    return {k: config[k] for k in keys if k in config}


def noise_study_in_report():
    """Is the noise study part of the default target and the report (noise_study.in_report)?"""
    return config["noise_study"]["in_report"]


def gap_benchmark_in_report():
    """Is the blind benchmark part of the default target and the report (gap_benchmark.in_report)?"""
    return config["gap_benchmark"]["in_report"]


def noise_report_inputs(wildcards):
    """The study's dataset when it is part of the report, else nothing."""
    return {"dataset": "results/studies/noise_study.nc"} if noise_study_in_report() else {}
