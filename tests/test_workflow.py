"""The workflow end to end on the default rig data (integration tests)."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.workflow


def make_project(tmp: Path, overrides: dict | None = None) -> Path:
    shutil.copy(ROOT / "Snakefile", tmp / "Snakefile")
    shutil.copytree(ROOT / "workflow", tmp / "workflow", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    shutil.copytree(ROOT / "paper", tmp / "paper")
    (tmp / "config").mkdir()
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    # the blind gap benchmark (about 45 min) stays out of the tests' report; tests/test_gap.py checks the diagnosis
    cfg["gap_benchmark"]["in_report"] = False
    cfg["noise_study"]["in_report"] = False  # the 30-job study likewise; tests/test_studies.py runs a small one
    for dotted, value in (overrides or {}).items():
        d = cfg
        *head, last = dotted.split(".")
        for k in head:
            d = d[k]
        d[last] = value
    (tmp / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
    return tmp


def snakemake(cwd: Path, *args) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(cwd / "workflow")}
    return subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def default_run(tmp_path_factory):
    proj = make_project(tmp_path_factory.mktemp("default"))
    res = snakemake(proj)
    assert res.returncode == 0, res.stderr[-3000:]
    return proj


def test_linear_chain_recovers_rig_truth(default_run):
    s = json.loads((default_run / "results" / "summary.json").read_text())
    f_id, f_true = s["natural_frequencies_hz"], s["truth"]["natural_frequencies_hz"]
    assert len(f_id) == 3
    for a, b in zip(f_id, f_true):
        assert abs(a / b - 1) < 0.003
    k_t, k_t_true = s["stiction"]["k_t"], s["truth"]["stiction"]["k_t"]
    assert abs(k_t / k_t_true - 1) < 0.03
    k_n_true = s["truth"]["stiction"]["k_n"]
    if "k_n" in s["stiction"]:
        lo, hi = s["stiction"]["k_n_interval"]
        assert lo <= k_n_true <= hi
    else:
        assert s["stiction"]["k_n_lower_bound"] <= k_n_true


def test_outputs_for_people_exist(default_run):
    import pandas as pd

    t1 = pd.read_csv(default_run / "results/tables/table1.csv")
    assert {"paper_hz", "identified_hz", "truth_hz", "diff_vs_paper_pct", "diff_vs_truth_pct"} <= set(t1.columns)
    assert (t1["diff_vs_paper_pct"].abs() < 1.0).all()  # the rig's linear frequencies meet Table 1 within 1 %
    t3 = pd.read_csv(default_run / "results/tables/table3.csv")
    assert set(t3["parameter"]) == {"k_t", "k_n"}
    assert (default_run / "results/tables/paper_consistency.csv").stat().st_size > 0
    assert (default_run / "results/figures/fig03_frf.png").stat().st_size > 10000


def test_rerun_same_seed_identical_other_seed_differs(default_run, tmp_path):
    import xarray as xr

    (tmp_path / "same").mkdir()
    (tmp_path / "other").mkdir()
    same = make_project(tmp_path / "same")
    other = make_project(tmp_path / "other", {"seed": 1234})
    targets = ("results/linear/stiction.nc", "data/raw/lc1.nc")
    for proj in (same, other):
        res = snakemake(proj, *targets)
        assert res.returncode == 0, res.stderr[-3000:]

    def numbers(proj):
        st = xr.load_dataset(proj / targets[0], engine="netcdf4")
        raw = xr.load_dataset(proj / targets[1], engine="netcdf4")
        return float(st["k_t"]), st["identified_frequency"].values, raw["acceleration"].values

    k0, f0, a0 = numbers(default_run)
    k1, f1, a1 = numbers(same)
    k2, f2, a2 = numbers(other)
    assert k1 == k0 and np.array_equal(f1, f0) and np.array_equal(a1, a0)
    assert k2 != k0 and not np.array_equal(f2, f0) and not np.allclose(a2, a0)


@pytest.mark.parametrize(
    "overrides, message",
    [
        ({"structure.beam.length_m": -0.6}, "length_m"),
        ({"structure.sensors.positions_m": [0.55, 0.3, 0.9]}, "positions_m[2] = 0.9 m lies outside the beam"),
        ({"linear_modes.n_modes": 4, "modal.n_modes": 3}, "linear_modes.n_modes = 4 exceeds the number of sensors"),
        ({"frf.segmnt_length": 8192}, "segmnt_length"),
    ],
)
def test_bad_config_fails_before_any_rule(tmp_path, overrides, message):
    proj = make_project(tmp_path, overrides)
    res = snakemake(proj, "-n")
    assert res.returncode != 0
    assert message in res.stderr + res.stdout
    assert not (proj / "results").exists() and not (proj / "data").exists()


def test_rig_target_makes_raw_records_only(tmp_path):
    proj = make_project(tmp_path)
    res = snakemake(proj, "rig")
    assert res.returncode == 0, res.stderr[-3000:]
    raw = sorted(p.name for p in (proj / "data" / "raw").iterdir())
    assert raw == ["lc1.nc", "lc2.nc", "lc3.nc", "random_test.nc"]
    assert not (proj / "results").exists()


def test_default_records_meet_table2(default_run):
    s = json.loads((default_run / "results" / "summary.json").read_text())
    for case, (a1, a2) in {"lc1": (14, 34), "lc2": (17.5, 42.5), "lc3": (20, 50)}.items():
        got = s["load_cases"][case]
        assert abs(got["A1_m_per_s2"] / a1 - 1) < 0.01 and abs(got["A2_m_per_s2"] / a2 - 1) < 0.01
        tr = s["truth_load_cases"][case]
        assert tr["N_min_n"] > 0 and tr["max_S_over_mu_N"] > 0.99


def test_new_load_case_runs_only_its_jobs(default_run):
    cfg = yaml.safe_load((default_run / "config" / "config.yaml").read_text())
    cfg["load_cases"]["lc4"] = {"A1_m_per_s2": 12.0, "A2_m_per_s2": 30.0}
    alt = default_run / "config" / "with_lc4.yaml"
    alt.write_text(yaml.safe_dump(cfg))
    res = snakemake(default_run, "--configfile", str(alt), "-n", "--quiet", "rules")
    assert res.returncode == 0, res.stderr[-3000:]
    out = res.stdout + res.stderr
    jobs = {line.split()[0]: int(line.split()[1]) for line in out.splitlines()
            if len(line.split()) == 2 and line.split()[1].isdigit()}
    assert jobs.get("rig_dual_sine") == 1 and jobs.get("raw_check") == 1
    assert "rig_random_test" not in jobs and "frf" not in jobs and "stiction_stiffness" not in jobs
    assert "friction_fit" not in jobs  # the calibration fit stays; lc4 is validated with it


def test_measured_case_with_wrong_unit_names_file(default_run, tmp_path):
    import xarray as xr

    proj = make_project(tmp_path)
    ds = xr.load_dataset(default_run / "data" / "raw" / "lc1.nc", engine="netcdf4")
    ds["acceleration"].attrs["units"] = "g"
    (proj / "measured").mkdir()
    ds.to_netcdf(proj / "measured" / "lc7.nc", engine="netcdf4")
    cfg = yaml.safe_load((proj / "config" / "config.yaml").read_text())
    cfg["load_cases"] = {"lc7": {"source": "measured", "file": "measured/lc7.nc"}}
    (proj / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
    res = snakemake(proj, "results/lc7/raw_check.nc")
    assert res.returncode != 0
    log = (proj / "logs" / "raw_check_lc7.log").read_text() + res.stderr
    assert "measured/lc7.nc" in log and "convert to 'm/s^2'" in log
    assert not (proj / "results" / "lc7" / "raw_check.nc").exists()


def test_invalid_measured_records_stop_only_their_case_and_say_why(tmp_path):
    from test_importers import dual_sine

    proj = make_project(tmp_path)
    ds = dual_sine()  # a valid synthetic record on the model's sensor layout
    (proj / "measured").mkdir()
    clipped = ds.copy(deep=True)
    a = clipped["acceleration"].values
    a[2] = np.clip(a[2], None, 0.7 * a[2].max())
    clipped.to_netcdf(proj / "measured" / "lc7.nc", engine="netcdf4")
    wrong_f = ds.copy(deep=True)
    wrong_f.attrs["excitation_frequency_hz"] = 55.0
    wrong_f.to_netcdf(proj / "measured" / "lc8.nc", engine="netcdf4")
    ds.to_netcdf(proj / "measured" / "lc9.nc", engine="netcdf4")
    cfg = yaml.safe_load((proj / "config" / "config.yaml").read_text())
    cfg["load_cases"] = {c: {"source": "measured", "file": f"measured/{c}.nc"} for c in ("lc7", "lc8", "lc9")}
    (proj / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
    res = snakemake(proj, "--keep-going", *[f"results/{c}/raw_check.nc" for c in ("lc7", "lc8", "lc9")])
    assert res.returncode != 0
    log7 = (proj / "logs" / "raw_check_lc7.log").read_text()  # the rule's log says it, not only stderr
    assert "measured/lc7.nc: channel a3: clipping check failed" in log7
    log8 = (proj / "logs" / "raw_check_lc8.log").read_text()
    assert "measured/lc8.nc: channel force: excitation frequency check failed" in log8 and "declares 55 Hz" in log8
    assert not (proj / "results/lc7/raw_check.nc").exists() and not (proj / "results/lc8/raw_check.nc").exists()
    assert (proj / "results/lc9/raw_check.nc").exists()  # the valid case went on


def test_working_method_recovers_contact_forces(default_run):
    s = json.loads((default_run / "results" / "summary.json").read_text())
    for case in ("lc1", "lc2", "lc3"):
        w = s["contact_forces"][case]
        assert w["S_nrmse"] < 0.05 and w["N_nrmse"] < 0.05 and w["xi_nrmse"] < 0.03
        assert "eta_nrmse" in w
        p = s["contact_forces_paper"][case]
        assert {"S_nrmse", "N_nrmse", "xi_nrmse", "eta_nrmse", "nnm_phase_spread_deg", "reconstruction_nrmse"} <= set(p)
    for fig in ("fig04_generalized_coordinates", "fig05_reconstruction", "fig06_contact_forces"):
        assert (default_run / "results" / "figures" / f"{fig}.png").stat().st_size > 10000


def test_tenfold_noise_runs_and_reports_larger_errors(default_run, tmp_path):
    import xarray as xr

    proj = make_project(tmp_path, {"rig.noise_fraction": 0.05, "load_cases": {"lc1": {"A1_m_per_s2": 14.0, "A2_m_per_s2": 34.0}}})
    res = snakemake(proj, "results/lc1/contact_forces.nc")
    assert res.returncode == 0, res.stderr[-3000:]
    noisy = xr.load_dataset(proj / "results/lc1/contact_forces.nc", engine="netcdf4").attrs
    clean = xr.load_dataset(default_run / "results/lc1/contact_forces.nc", engine="netcdf4").attrs
    assert noisy["S_nrmse"] > clean["S_nrmse"] and noisy["N_nrmse"] > clean["N_nrmse"]


def test_friction_law_recovers_rig_truth_and_validates(default_run):
    import pandas as pd

    s = json.loads((default_run / "results" / "summary.json").read_text())
    fr = s["friction"]
    assert abs(fr["mu"] / 0.397 - 1) < 0.02
    assert abs(fr["kappa"] / 0.284 - 1) < 0.10
    e0_true = 3.857e7 * (1 - np.exp(-2.547e5 * 70.0 / 3.857e7))
    assert abs(fr["e0_at_preload"] / e0_true - 1) < 0.05
    lo, hi = fr["intervals"]["e_t"]
    assert lo <= 1.0e4 <= hi and "e_t" in fr["only_bounded"]
    assert s["validation_nrmse"]["lc2"] <= 0.05 and s["validation_nrmse"]["lc3"] <= 0.05
    t4 = pd.read_csv(default_run / "results" / "tables" / "table4.csv")
    assert {"identified", "interval_low", "interval_high", "paper_value", "truth"} <= set(t4.columns)
    for fig in ("fig07_e0", "fig08_s_xi", "fig09_s_xidot", "friction_convergence"):
        assert (default_run / "results" / "figures" / f"{fig}.png").stat().st_size > 10000


def test_report_pdf_and_generated_numbers(default_run):
    pdf = default_run / "results" / "report" / "report.pdf"
    assert pdf.stat().st_size > 100000
    numbers = (default_run / "results" / "report" / "numbers.tex").read_text()
    for macro in ("\\freqone", "\\kt", "\\fitmu", "\\lconeworkS", "\\consNmaxerr"):
        assert f"\\newcommand{{{macro}}}" in numbers


def test_audit_passes_clean_and_flags_a_hand_edit(default_run, tmp_path):
    import netCDF4

    from contactid.audit import audit

    clean = audit([default_run / "results", default_run / "data"], root=default_run)
    assert len(clean) > 20 and (clean["status"] == "ok").all(), clean[clean["status"] != "ok"]
    edited = tmp_path / "validation.nc"
    shutil.copy(default_run / "results" / "lc2" / "validation.nc", edited)
    with netCDF4.Dataset(edited, "a") as nc:
        nc["S_predicted"][0] = nc["S_predicted"][0] + 1.0
    row = audit([edited]).iloc[0]
    assert row["status"] == "flagged" and "edited by hand" in row["problems"]


def test_gap_diagnosis_of_default_data_names_no_effect(default_run):
    d = json.loads((default_run / "results" / "gap" / "diagnosis.json").read_text())
    assert d["verdict"] == "none", d["reason"]  # effect-free rig data: no false alarm
    assert {"verdict", "ranking", "where"} <= set(d)
    assert {r["effect"] for r in d["ranking"]} == {"structural_damping", "normal_contact_damping", "viscous_friction",
                                                   "multi_asperity_friction", "transducer_mass_error",
                                                   "channel_time_skew", "contact_separation", "preload_drift"}
    for r in d["ranking"]:
        assert {"effect", "heldout_gap_before", "heldout_gap_after", "score"} <= set(r)
        assert r["heldout_gap_after"] > 0.5 * r["heldout_gap_before"]  # nothing explains what is not there
    assert d["where"]["heldout_gap_before"] < 0.01  # the identified model reproduces the held-out records
    assert d["where"]["place"] == "tangential_contact"
    for view in ("stages", "harmonics", "cycle", "force_state", "ranking", "shrink"):
        assert (default_run / "results" / "gap" / f"gap_{view}.png").stat().st_size > 10000
    tex = (default_run / "results" / "report" / "gap.tex").read_text()
    assert "Verdict" in tex and "Not built with this report" in tex


def test_changed_setting_changes_the_pdf_numbers_only_downstream(default_run):
    cfg = yaml.safe_load((default_run / "config" / "config.yaml").read_text())
    cfg["friction"]["generations"] = 15
    cfg["gap"]["candidates"] = ["viscous_friction"]  # the gap diagnosis reruns too; keep it short
    alt = default_run / "config" / "fewer_generations.yaml"
    alt.write_text(yaml.safe_dump(cfg))
    before = (default_run / "results" / "report" / "numbers.tex").read_text()
    dry = snakemake(default_run, "--configfile", str(alt), "-n", "--quiet", "rules")
    assert "friction_fit" in dry.stdout and "rig_dual_sine" not in dry.stdout and "contact_forces" not in dry.stdout
    res = snakemake(default_run, "--configfile", str(alt))
    assert res.returncode == 0, res.stderr[-3000:]
    after = (default_run / "results" / "report" / "numbers.tex").read_text()
    assert after != before


def test_snakemake_html_report(default_run):
    res = snakemake(default_run, "--report", "report.html")
    assert res.returncode == 0, res.stderr[-3000:]
    html = (default_run / "report.html").read_text(errors="replace")
    assert len(html) > 100000 and "fig06_contact_forces.png" in html


def test_changed_package_code_reruns_what_it_computed(default_run):
    module = default_run / "workflow" / "contactid" / "latex.py"
    original = module.read_text()
    try:
        module.write_text(original + "\n# a change of the package's code\n")
        dry = snakemake(default_run, "-n", "--quiet", "rules")
        assert dry.returncode == 0, dry.stderr[-2000:]
        assert "report_fragments" in dry.stdout and "rig_random_test" in dry.stdout
    finally:
        module.write_text(original)
    again = snakemake(default_run, "-n", "--quiet", "rules")
    # with the code restored, nothing upstream of the fit is planned (an earlier test changed a fit setting)
    assert "rig_random_test" not in again.stdout and "contact_forces" not in again.stdout


def test_gap_runs_on_a_directory_of_raw_files_alone(default_run, tmp_path):
    (tmp_path / "measured").mkdir()
    for f in ("random_test", "lc1", "lc2", "lc3"):
        shutil.copy(default_run / "data" / "raw" / f"{f}.nc", tmp_path / "measured" / f"{f}.nc")
    proj = make_project(tmp_path / "proj" if (tmp_path / "proj").mkdir() is None else None, {
        "random_test.source": "measured", "random_test.file": str(tmp_path / "measured" / "random_test.nc"),
        "load_cases": {c: {"source": "measured", "file": str(tmp_path / "measured" / f"{c}.nc")} for c in ("lc1", "lc2", "lc3")},
        "gap.candidates": ["viscous_friction"]})
    res = snakemake(proj, "gap")
    assert res.returncode == 0, res.stderr[-3000:]
    assert not (proj / "data").exists()  # nothing from the rig
    d = json.loads((proj / "results" / "gap" / "diagnosis.json").read_text())
    assert d["verdict"] == "none" and [r["effect"] for r in d["ranking"]] == ["viscous_friction"]


def test_no_rule_writes_to_its_own_inputs(default_run):
    res = snakemake(default_run, "--detailed-summary")
    assert res.returncode == 0, res.stderr[-3000:]
    rows = [line.split("\t") for line in res.stdout.splitlines()[1:] if "\t" in line]
    assert len(rows) > 30
    for out, _, rule, logs, inputs, *_ in rows:
        assert out not in inputs.split(","), f"rule {rule} reads its own output {out}"
        assert out not in logs.split(","), f"rule {rule} logs into its output {out}"


def test_imported_uff58_tdms_csv_give_the_same_contact_forces(default_run, tmp_path):
    """lc1's rig record written as a UFF58 file (accelerations in g), a TDMS file (voltages with
    sensitivities) and a CSV + sidecar YAML, imported by their rules, identify the same S(t)."""
    import xarray as xr

    from contactid.importers.export import export_record

    proj = make_project(tmp_path)
    (proj / "measured").mkdir()
    shutil.copy2(default_run / "data/raw/random_test.nc", proj / "measured/random_test.nc")  # keeps its mtime
    raw = xr.load_dataset(default_run / "data/raw/lc1.nc", engine="netcdf4")
    storages = {"uff58": {"acceleration": ("g", None, None)},
                "tdms": {"force": ("mV", 2.25, "mV/N"), "acceleration": ("mV", 10.2, "mV/g")}, "csv": None}
    cfg = yaml.safe_load((proj / "config" / "config.yaml").read_text())
    cfg["random_test"] = {**cfg["random_test"], "source": "measured", "file": "measured/random_test.nc"}
    cfg["load_cases"] = {}
    for case, fmt in zip(("lc1", "lc2", "lc3"), storages):
        block = export_record(raw, proj / "measured" / f"{case}.{fmt}", fmt, storages[fmt])
        block["file"] = f"measured/{case}.{fmt}"
        cfg["load_cases"][case] = block
    (proj / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
    # the linear chain of the same random test, as the default run computed it (newer than its input: not redone)
    shutil.copytree(default_run / "results/linear", proj / "results/linear")
    res = snakemake(proj, *[f"results/{c}/contact_forces.nc" for c in ("lc1", "lc2", "lc3")])
    assert res.returncode == 0, res.stderr[-3000:]
    for rule in ("import_uff58", "import_tdms", "import_csv"):
        assert rule in res.stdout + res.stderr
    S0 = xr.load_dataset(default_run / "results/lc1/contact_forces.nc", engine="netcdf4")["S"].values
    for c in ("lc1", "lc2", "lc3"):
        S = xr.load_dataset(proj / f"results/{c}/contact_forces.nc", engine="netcdf4")["S"].values
        nrmse = np.sqrt(np.mean((S - S0) ** 2)) / np.std(S0)
        print(f"{c} ({cfg['load_cases'][c]['format']}): S NRMSE against the netCDF original {nrmse:.2e}")
        assert nrmse < 1e-3
    assert not (proj / "data" / "truth").exists()  # nothing of the rig's truth for measured records
