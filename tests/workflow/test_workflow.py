"""The workflow end to end: the acceptance run, the whole workflow on the default config, against the rig's
truth (``default_run``), and integration tests on the small config .test/config_small.yaml (``small_run`` and
the projects of conftest.py's SHARED_RUNS, made and run in the background while other tests run; or projects of
their own). The shared projects are read only: a test that changes files, config or code works on a copy
(tests/workflow_projects.py)."""

import json
import shutil

import numpy as np
import pytest
import yaml
from workflow_projects import (
    NUMBERS,
    copy_project,
    make_project,
    project_config,
    small_project,
    snakemake,
)

pytestmark = pytest.mark.workflow


# ----------------------------------------------------------------------------------------------
# projects of their own
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "overrides, message",
    [
        ({"structure.beam.length_m": -0.6}, "length_m"),
        ({"linear_modes.n_modes": 4, "modal.n_modes": 3}, "linear_modes.n_modes = 4 exceeds the number of sensors"),
        ({"frf.segmnt_length": 8192}, "segmnt_length"),
    ],
)
def test_bad_config_fails_before_any_rule(tmp_path, overrides, message):
    # a schema error (type, unknown key) and a cross-field check stop snakemake itself; every check's message is
    # tested in tests/test_config.py
    proj = make_project(tmp_path, overrides)
    res = snakemake(proj, "-n")
    assert res.returncode != 0
    assert message in res.stderr + res.stdout
    assert not (proj / "results").exists() and not (proj / "data").exists()


def test_any_set_of_load_cases_plans_the_report_without_a_figure_case(tmp_path):
    """Two load cases of other names, calibrated on the second, nonlinear.figure_case left out (it falls back to the
    last case): the whole default target is planned, the report's fragments with it (the report rule read the key
    the schema does not default, a KeyError before any job)."""
    proj = make_project(
        tmp_path,
        {
            "load_cases": {
                "lc2": {"A1_m_per_s2": 17.5, "A2_m_per_s2": 42.5},
                "lc5": {"A1_m_per_s2": 20.0, "A2_m_per_s2": 50.0},
            },
            "nonlinear.calibration_case": "lc5",
        },
    )
    cfg_file = proj / "config" / "config.yaml"
    cfg = yaml.safe_load(cfg_file.read_text())
    cfg["nonlinear"].pop("figure_case")
    cfg_file.write_text(yaml.safe_dump(cfg))
    res = snakemake(proj, "-n", "--quiet", "rules")
    assert res.returncode == 0, res.stderr
    assert "report_fragments" in res.stdout


def test_rig_target_makes_raw_records_only_and_the_seed_makes_them(small_run, rig_run, other_seed_run):
    import xarray as xr

    # `snakemake rig` on the small config with two of its three load cases (workflow_projects.prepare_rig_run)
    raw = sorted(p.name for p in (rig_run / "data" / "raw").iterdir())
    assert raw == ["lc1.nc", "lc3.nc", "random_test.nc"]  # exactly the configured records
    assert not (rig_run / "results").exists()

    # the seed makes the records, in another project and whichever other load cases are configured: the small
    # run's seed gives the small run's records to the bit, seed 1234 (other_seed_run) other ones
    def arrays(proj, name):
        ds = xr.load_dataset(proj / "data/raw" / name, engine="netcdf4")
        return ds["acceleration"].values, ds["force"].values

    assert project_config(rig_run)["seed"] == project_config(small_run)["seed"]
    for name in raw:
        (a0, f0), (a1, f1) = arrays(small_run, name), arrays(rig_run, name)
        assert np.array_equal(a1, a0) and np.array_equal(f1, f0), name
    assert project_config(other_seed_run)["seed"] == 1234 != project_config(small_run)["seed"]
    (a0, f0), (a2, f2) = arrays(small_run, "lc1.nc"), arrays(other_seed_run, "lc1.nc")
    assert not np.allclose(a2, a0) and not np.allclose(f2, f0)


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
    cfg["nonlinear"].update(calibration_case="lc9", figure_case="lc9")  # cases the config has (config.check_config)
    (proj / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
    res = snakemake(proj, "--keep-going", *[f"results/{c}/raw_check.nc" for c in ("lc7", "lc8", "lc9")])
    assert res.returncode != 0
    log7 = (proj / "logs" / "raw_check_lc7.log").read_text()  # the rule's log says it, not only stderr
    assert "measured/lc7.nc: channel a3: clipping check failed" in log7
    log8 = (proj / "logs" / "raw_check_lc8.log").read_text()
    assert "measured/lc8.nc: channel force: excitation frequency check failed" in log8 and "declares 55 Hz" in log8
    assert not (proj / "results/lc7/raw_check.nc").exists() and not (proj / "results/lc8/raw_check.nc").exists()
    assert (proj / "results/lc9/raw_check.nc").exists()  # the valid case went on


# each odd record as a measured load case of one project, checked in one run (--keep-going): (defect, what the rule's
# log must say, whether the record is refused); the checks' own tests are in tests/test_raw_checks.py
ODD_RECORDS = {
    "lc4": ("dead channel", ["channel a2: dead-channel check failed", "dead sensor, cable"], True),
    "lc5": ("sampling rate and time axis doubled", ["sampling rate check failed", "2 times the declared"], True),
    "lc6": ("no units attribute", ["'acceleration' has no units attribute; state the units"], True),
    "lc7": ("noise-free (a simulator's)", [], False),
    "lc8": ("force offset 2 N", ["force: mean 2", "offset or drift"], False),
}


def _odd_record(case):
    from test_importers import dual_sine

    ds = dual_sine(noise=0.0 if case == "lc7" else 0.005)
    if case == "lc4":
        ds["acceleration"].values[1] = 0.0
    elif case == "lc5":
        ds.attrs["sampling_rate_hz"] = 2 * ds.attrs["sampling_rate_hz"]
        ds = ds.assign_coords(time=("time", ds["time"].values / 2, ds["time"].attrs))
    elif case == "lc6":
        del ds["acceleration"].attrs["units"]
    elif case == "lc8":
        ds["force"].values[:] += 2.0
    return ds


def test_odd_records_are_refused_or_warned_with_the_cause_that_fits(tmp_path):
    """Odd measured records, each a load case of one project: a refused record stops its own case (exit status not
    0, no dataset, the log naming the cause and the fix), an accepted one is checked with its warnings in the dataset,
    and a result computed before stays as it was."""
    proj = make_project(tmp_path)
    (proj / "measured").mkdir()
    for case in ODD_RECORDS:
        _odd_record(case).to_netcdf(proj / "measured" / f"{case}.nc", engine="netcdf4")
    cfg = yaml.safe_load((proj / "config" / "config.yaml").read_text())
    cfg["load_cases"] = {c: {"source": "measured", "file": f"measured/{c}.nc"} for c in ODD_RECORDS}
    cfg["nonlinear"].update(calibration_case="lc7", figure_case="lc7")
    (proj / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
    earlier = proj / "results" / "lc4" / "contact_forces.nc"  # a result of an earlier run of the same case
    earlier.parent.mkdir(parents=True)
    earlier.write_bytes(b"computed before")
    stamp = earlier.stat().st_mtime_ns
    res = snakemake(proj, "--keep-going", *[f"results/{c}/raw_check.nc" for c in ODD_RECORDS])
    assert res.returncode != 0
    for case, (defect, words, refused) in ODD_RECORDS.items():
        log = (proj / "logs" / f"raw_check_{case}.log").read_text()
        assert (proj / "results" / case / "raw_check.nc").exists() != refused, (defect, log)
        assert "clipping" not in log, (defect, log)
        if not refused:
            import xarray as xr

            warnings = json.loads(xr.load_dataset(proj / "results" / case / "raw_check.nc").attrs["warnings"])
            log = "\n".join(warnings)
        for w in words:
            assert w in log, (defect, w, log)
    assert earlier.read_bytes() == b"computed before" and earlier.stat().st_mtime_ns == stamp


# ----------------------------------------------------------------------------------------------
# on the small config: against the shared small run
# ----------------------------------------------------------------------------------------------


def test_measured_case_with_wrong_unit_names_file(small_run, tmp_path):
    import xarray as xr

    proj = small_project(tmp_path)
    ds = xr.load_dataset(small_run / "data" / "raw" / "lc1.nc", engine="netcdf4")
    ds["acceleration"].attrs["units"] = "g"
    (proj / "measured").mkdir()
    ds.to_netcdf(proj / "measured" / "lc7.nc", engine="netcdf4")
    cfg = yaml.safe_load((proj / "config" / "config.yaml").read_text())
    cfg["load_cases"] = {"lc7": {"source": "measured", "file": "measured/lc7.nc"}}
    cfg["nonlinear"].update(calibration_case="lc7", figure_case="lc7")
    (proj / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
    res = snakemake(proj, "results/lc7/raw_check.nc")
    assert res.returncode != 0
    log = (proj / "logs" / "raw_check_lc7.log").read_text() + res.stderr
    assert "measured/lc7.nc" in log and "convert to 'm/s^2'" in log
    assert not (proj / "results" / "lc7" / "raw_check.nc").exists()


def test_gap_runs_on_a_directory_of_raw_files_alone(measured_run):
    # every record a measured file, none from the rig (workflow_projects.prepare_measured_run): `snakemake gap`
    proj, _ = measured_run
    # nothing from the rig (data/raw, data/truth): data/ holds only the importers' netCDF files
    assert sorted(p.name for p in (proj / "data").iterdir()) == ["imported"]
    d = json.loads((proj / "results" / "gap" / "diagnosis.json").read_text())
    # the library in use (gap.candidates) and the form candidate, tried in every diagnosis
    # (story_decisions.beyond_model_form)
    assert d["verdict"] == "none" and {r["effect"] for r in d["ranking"]} == {"viscous_friction", "structural_damping"}
    assert [t["test"] for t in d["trace"]][0] == "held_out" and d["resolution"]["heldout_gap"] > 0


def test_measured_files_are_inputs_by_their_content(measured_run, tmp_path):
    """On a project that has run: a config whose measured file does not exist stops snakemake before any job, naming
    the key and the path, and the results stand as they were; a record replaced by another with the same size and
    modification time (cp -p, rsync -a, a restored backup) plans its import and everything after it again; a key
    written twice in a --configfile is refused with its lines."""
    import os

    proj = copy_project(measured_run[0], tmp_path / "proj")
    summary = proj / "results" / "summary.json"
    before = (summary.read_bytes(), summary.stat().st_mtime_ns)
    assert "Nothing to be done" in snakemake(proj, "-n").stdout
    cfg = project_config(proj)
    (tmp_path / "typo.yaml").write_text(
        yaml.safe_dump({"load_cases": {"lc3": {**cfg["load_cases"]["lc3"], "file": "measured/lc_3.csv"}}})
    )
    for target in ((), ("gap",)):
        res = snakemake(proj, *target, "--configfile", str(tmp_path / "typo.yaml"))
        assert res.returncode != 0
        assert "load_cases.lc3.file = 'measured/lc_3.csv': does not exist" in res.stderr + res.stdout
        assert "did you mean 'measured/lc3.csv'" in res.stderr + res.stdout
    assert (summary.read_bytes(), summary.stat().st_mtime_ns) == before
    csv = proj / "measured" / "lc3.csv"
    st = csv.stat()
    text = csv.read_text().splitlines()
    csv.write_text("\n".join(text[:1] + text[2:] + text[1:2]) + "\n")  # the same bytes in another order
    os.utime(csv, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert csv.stat().st_size == st.st_size and csv.stat().st_mtime_ns == st.st_mtime_ns
    plan = snakemake(proj, "-n", "--quiet", "rules").stdout
    for rule in ("import_csv", "raw_check", "contact_forces", "gap_diagnosis", "summary"):
        assert rule in plan, (rule, plan)
    assert "import_uff58_frf" not in plan  # the random test did not change
    (tmp_path / "dup.yaml").write_text("gap: {candidates: [viscous_friction]}\ngap: {candidates: []}\n")
    res = snakemake(proj, "-n", "--configfile", str(tmp_path / "dup.yaml"))
    assert res.returncode != 0 and f"{tmp_path / 'dup.yaml'}:2: key 'gap' repeats line 1" in res.stderr + res.stdout


def test_report_of_measured_records_says_no_truth_is_known(measured_run):
    """Every record measured: the report compiles, says there is no truth, and prints no empty truth column."""
    proj, _ = measured_run
    report = proj / "results" / "report"
    assert (report / "report.pdf").stat().st_size > 50_000
    numbers = (report / "numbers.tex").read_text()
    assert "\\rigtruthfalse" in numbers and "truefreq" not in numbers
    for table in ("table1.tex", "table3.tex", "table4.tex"):
        assert "truth" not in (report / table).read_text(), table
    assert "no truth is known" in (report / "contact.tex").read_text()


def test_imported_uff58_tdms_csv_give_the_same_contact_forces(small_run, measured_run):
    """Each load case's rig record, written as a UFF58 file (accelerations in g), a TDMS file (voltages
    with sensitivities) or a CSV + sidecar YAML and imported by its rule, identifies the same S(t) as the
    netCDF original (the linear chain redone from the same random test's FRFs, imported from a UFF58 file)."""
    import xarray as xr

    proj, out = measured_run
    cfg = project_config(proj)
    for rule in ("import_uff58", "import_tdms", "import_csv"):
        assert rule in out
    for c in ("lc1", "lc2", "lc3"):
        S0 = xr.load_dataset(small_run / f"results/{c}/contact_forces.nc", engine="netcdf4")["S"].values
        S = xr.load_dataset(proj / f"results/{c}/contact_forces.nc", engine="netcdf4")["S"].values
        nrmse = np.sqrt(np.mean((S - S0) ** 2)) / np.std(S0)
        print(f"{c} ({cfg['load_cases'][c]['format']}): S NRMSE against the netCDF original {nrmse:.2e}")
        assert nrmse < 1e-3
    assert not (proj / "data" / "truth").exists()  # nothing of the rig's truth for measured records


# ----------------------------------------------------------------------------------------------
# the acceptance run: the whole workflow on config/config.yaml against the rig's truth
# ----------------------------------------------------------------------------------------------


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


def test_every_units_attribute_parses_and_every_variable_has_one_unit(default_run):
    """Every ``units`` attribute of every dataset the acceptance run wrote (data/ and results/, variables and
    coordinates) is a unit pint reads (mass-normalised coordinates as kg^0.5 m, kg^-0.5; no "mixed" vectors: the
    friction law's parameters, the response control's history and the force-state maps are one variable per
    quantity)."""
    import pint
    import xarray as xr

    ureg = pint.UnitRegistry()
    seen = set()
    for f in sorted([*(default_run / "data").rglob("*.nc"), *(default_run / "results").rglob("*.nc")]):
        with xr.open_dataset(f, engine="netcdf4") as ds:
            for name, var in {**ds.data_vars, **ds.coords}.items():
                units = var.attrs.get("units")
                if units is None:
                    continue
                seen.add(units)
                try:
                    ureg.parse_expression(units) if units == "1" else ureg.parse_units(units)
                except Exception as exc:  # pint raises several kinds
                    raise AssertionError(f"{f.relative_to(default_run)}: {name}: units {units!r}: {exc}") from exc
    assert {"N", "m/s^2", "kg^-0.5", "N/m", "1/m"} <= seen, seen
    fit = xr.load_dataset(default_run / "results/friction/friction_fit.nc", engine="netcdf4")
    assert [fit[p].attrs["units"] for p in ("e_f", "k_c", "e_t", "kappa", "mu")] == ["N/m", "1/m", "N/m", "1", "1"]
    assert list(fit["estimate"].values) == ["value", "interval_low", "interval_high"]


def test_the_damping_at_test_level_is_the_random_tests_on_a_rig_damped_as_the_model(default_run):
    import xarray as xr

    # the default rig's damping has the identified model's form: the law's misfit is least at the random test's ratios
    ds = xr.load_dataset(default_run / "results/friction/test_damping.nc", engine="netcdf4")
    assert float(ds["damping_scale"]) == pytest.approx(1.0, abs=0.03)
    assert float(ds["damping_scale_applied"]) == pytest.approx(1.0, abs=0.03)
    lo, hi = ds["damping_scale_interval"].values
    assert lo <= 1.0 <= hi and hi - lo < 0.15
    assert ds.attrs["driven_mode"] == 1  # 54.4 Hz drives the first mode
    modal = xr.load_dataset(default_run / "results/linear/modal.nc", engine="netcdf4")
    np.testing.assert_allclose(ds["damping_ratio_test"].values, modal["damping_ratio"].values, rtol=0.03)
    # the diagnosed model keeps the random test's ratios unless the held-out records confirmed a factor
    updated = json.loads((default_run / "results/gap/updated_model.json").read_text())
    assert updated["damping_at_test_level"]["applied"] == bool(ds.attrs["accepted"]) and not ds.attrs["accepted"]
    summary = json.loads((default_run / "results" / "summary.json").read_text())
    assert summary["friction"]["test_damping"]["applied_scale"] == float(ds["damping_scale_applied"])


def test_default_records_meet_table2(default_run):
    s = json.loads((default_run / "results" / "summary.json").read_text())
    for case, (a1, a2) in {"lc1": (14, 34), "lc2": (17.5, 42.5), "lc3": (20, 50)}.items():
        got = s["load_cases"][case]
        assert abs(got["A1_m_per_s2"] / a1 - 1) < 0.01 and abs(got["A2_m_per_s2"] / a2 - 1) < 0.01
        tr = s["truth_load_cases"][case]
        assert tr["N_min_n"] > 0 and tr["max_S_over_mu_N"] > 0.99


def _planned_jobs(res) -> dict:
    """{rule: job count} of a dry run's job table (``snakemake -n --quiet rules``)."""
    return {
        line.split()[0]: int(line.split()[1])
        for line in (res.stdout + res.stderr).splitlines()
        if len(line.split()) == 2 and line.split()[1].isdigit()
    }


def test_new_load_case_runs_only_its_jobs(default_run, tmp_path):
    cfg = yaml.safe_load((default_run / "config" / "config.yaml").read_text())
    cfg["load_cases"]["lc4"] = {"A1_m_per_s2": 12.0, "A2_m_per_s2": 30.0}
    alt = tmp_path / "with_lc4.yaml"  # a dry run: the shared project stays untouched
    alt.write_text(yaml.safe_dump(cfg))
    res = snakemake(default_run, "--configfile", str(alt), "-n", "--quiet", "rules")
    assert res.returncode == 0, res.stderr[-3000:]
    jobs = _planned_jobs(res)
    assert jobs.get("rig_dual_sine") == 1 and jobs.get("raw_check") == 1
    assert "rig_random_test" not in jobs and "frf" not in jobs and "stiction_stiffness" not in jobs
    assert "friction_fit" not in jobs  # the calibration fit stays; lc4 is validated with it


def test_working_method_recovers_contact_forces(default_run):
    s = json.loads((default_run / "results" / "summary.json").read_text())
    for case in ("lc1", "lc2", "lc3"):
        w = s["contact_forces"][case]
        assert w["S_nrmse"] < 0.05 and w["N_nrmse"] < 0.05 and w["xi_nrmse"] < 0.03
        assert "eta_nrmse" in w
        # eta moves by far more than 10 % over the structures the random test allows: not observable (issue 15)
        assert w["eta_spread_over_structures"] > 0.5 and not w["eta_observable"]
        p = s["contact_forces_paper"][case]
        assert {"S_nrmse", "N_nrmse", "xi_nrmse", "eta_nrmse", "nnm_phase_spread_deg", "reconstruction_nrmse"} <= set(p)
    for fig in ("fig04_generalized_coordinates", "fig05_reconstruction", "fig06_contact_forces"):
        assert (default_run / "results" / "figures" / f"{fig}.png").stat().st_size > 10000


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
    # the intervals with the model-form term hold the truth and are wider than the profile-likelihood ones
    mf = fr["model_form_intervals"]
    for name, truth in (("mu", 0.397), ("kappa", 0.284), ("e0", e0_true)):
        lo, hi = mf[name]["interval"]
        assert lo < truth < hi
    assert mf["mu"]["interval"][0] < fr["intervals"]["mu"][0] and mf["mu"]["interval"][1] > fr["intervals"]["mu"][1]
    # what the data bind (the rig's lever arm, 4.58 mm, is the model's here): held, and narrower than mu's and e_0's,
    # which open with the lever arm the random test leaves free
    a = 0.00458
    for name, truth, par in (("mu_a", 0.397 * a, "mu"), ("e0_a2", e0_true * a**2, "e0")):
        lo, hi = mf[name]["interval"]
        assert lo < truth < hi, (name, lo, truth, hi)
        plo, phi = mf[par]["interval"]
        assert (hi - lo) / mf[name]["value"] < 0.5 * (phi - plo) / mf[par]["value"], name
    for fig in ("fig07_e0", "fig08_s_xi", "fig09_s_xidot", "friction_convergence"):
        assert (default_run / "results" / "figures" / f"{fig}.png").stat().st_size > 10000
    # the rig is the model: both fits pass their model checks, and the report says so
    checks = {c["check"]: c for c in s["model_checks"]}
    assert set(checks) == {"stiffness_fit", "friction_fit"} and all(c["passed"] for c in checks.values())
    assert checks["friction_fit"]["value"] == fr["misfit_nrmse"] and checks["friction_fit"]["limit"] == 0.01
    assert "Model checks." in (default_run / "results" / "report" / "datachecks.tex").read_text()


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
    assert {r["effect"] for r in d["ranking"]} == {
        "structural_damping",
        "normal_contact_damping",
        "viscous_friction",
        "multi_asperity_friction",
        "transducer_mass_error",
        "channel_time_skew",
        "contact_separation",
        "preload_drift",
        "beam_shortening",
        "channel_gain_error",
    }
    for r in d["ranking"]:
        assert {"effect", "heldout_gap_before", "heldout_gap_after", "score"} <= set(r)
        assert r["heldout_gap_after"] > 0.5 * r["heldout_gap_before"]  # nothing explains what is not there
    assert d["where"]["heldout_gap_before"] < 0.01  # the identified model reproduces the held-out records
    # eta moves far more than 10 % over the structures the random test allows: the direction stays open
    assert not d["where"]["eta_observability"]["observable"] and d["where"]["place"] == "contact"
    assert min(d["where"]["eta_observability"]["model_spread"].values()) > 0.5
    # nothing to explain: no model update, no step, the gap at the floor
    assert d["where"]["model_updating"]["accepted"] is False
    assert d["explanation"] == [] and d["remaining_gap"]["at_floor"] and d["remaining_gap"]["share"] == 1.0
    for view in ("stages", "harmonics", "cycle", "force_state", "ranking", "shrink", "explanation"):
        assert (default_run / "results" / "gap" / f"gap_{view}.png").stat().st_size > 10000
    tex = (default_run / "results" / "report" / "gap.tex").read_text()
    assert "Verdict" in tex and "Not built with this report" in tex


def test_snakemake_html_report(default_run, tmp_path):
    res = snakemake(default_run, "--report", str(tmp_path / "report.html"))  # written outside the shared project
    assert res.returncode == 0, res.stderr[-3000:]
    html = (tmp_path / "report.html").read_text(errors="replace")
    assert len(html) > 100000 and "fig06_contact_forces.png" in html


def test_no_rule_writes_to_its_own_inputs(default_run):
    res = snakemake(default_run, "--detailed-summary")
    assert res.returncode == 0, res.stderr[-3000:]
    rows = [line.split("\t") for line in res.stdout.splitlines()[1:] if "\t" in line]
    assert len(rows) > 30
    for out, _, rule, logs, inputs, *_ in rows:
        assert out not in inputs.split(","), f"rule {rule} reads its own output {out}"
        assert out not in logs.split(","), f"rule {rule} logs into its output {out}"


def test_changed_setting_changes_the_pdf_numbers_only_downstream(default_run, lower_confidence_run):
    # a copy of the acceptance run, its PDF's numbers made again with friction.confidence 0.9 given by --configfile
    # (workflow_projects.prepare_lower_confidence_run): the fit and what follows it run again, nothing before it
    proj, out = lower_confidence_run
    assert "rule friction_fit:" in out
    assert "rule rig_dual_sine:" not in out and "rule contact_forces:" not in out and "rule frf:" not in out
    assert (proj / NUMBERS).read_text() != (default_run / NUMBERS).read_text()


def test_changed_package_code_reruns_what_it_computed(default_run, tmp_path):
    proj = copy_project(default_run, tmp_path / "proj")  # a copy: the acceptance run's code stays as it is
    module = proj / "workflow" / "contactid" / "latex.py"
    original = module.read_text()
    module.write_text(original + "\n# a change of the package's code\n")
    dry = snakemake(proj, "-n", "--quiet", "rules")
    assert dry.returncode == 0, dry.stderr[-2000:]
    assert "report_fragments" in dry.stdout and "rig_random_test" in dry.stdout
    module.write_text(original)
    again = snakemake(proj, "-n", "--quiet", "rules")
    assert again.returncode == 0, again.stderr[-2000:]
    # with the code restored, nothing is planned again
    assert "rig_random_test" not in again.stdout and "contact_forces" not in again.stdout
    assert "report_fragments" not in again.stdout


def test_chain_on_measured_frfs_identifies_the_time_records_modes(small_run, measured_run):
    """The measured run's random test is the small run's FRFs as a UFF58 file (function types 4 and 6;
    workflow_projects.prepare_measured_run): import_uff58_frf (no rig, no time-record checks), modal and the
    stiffness fit identify the small run's natural frequencies and damping; the FRFs written back out
    (frf_measured.uff, frf_synthesised.uff) read back with pyuff on the same lines."""
    import xarray as xr
    from contactid.linear_chain import complex_frf
    from test_importers import _frf_sets
    from workflow_projects import FRF_FILE_TARGETS

    proj, log = measured_run
    out = FRF_FILE_TARGETS[1:]
    frf = xr.load_dataset(small_run / "results/linear/frf.nc", engine="netcdf4")
    assert "import_uff58_frf" in log and "rig_random_test" not in log and "rule frf:" not in log
    modal = xr.load_dataset(proj / "results/linear/modal.nc", engine="netcdf4")
    ref = xr.load_dataset(small_run / "results/linear/modal.nc", engine="netcdf4")
    np.testing.assert_allclose(modal["natural_frequency"].values, ref["natural_frequency"].values, rtol=1e-6)
    np.testing.assert_allclose(modal["damping_ratio"].values, ref["damping_ratio"].values, rtol=1e-6)
    imported = xr.load_dataset(proj / "results/linear/frf.nc", engine="netcdf4")
    assert imported.attrs["producer_rule"] == "import_uff58_frf" and "measured/frf.uff" in imported.attrs["frf_source"]
    assert (proj / "results/linear/stiction.nc").exists() and not (proj / "data/raw").exists()
    measured, synthesised = (_frf_sets(proj / p) for p in out)
    assert [s["func_type"] for s in measured] == [4, 4, 4, 6, 6, 6] and [s["func_type"] for s in synthesised] == [4] * 3
    for i in range(3):
        np.testing.assert_array_equal(measured[i]["data"], complex_frf(frf)[i])
        np.testing.assert_array_equal(measured[3 + i]["data"], frf["coherence"].values[i])
        np.testing.assert_array_equal(synthesised[i]["x"], frf["frequency"].values)


def test_no_table_cell_prints_more_digits_than_its_interval_supports(default_run):
    """Tables 3, 4 and 8 of the acceptance run's report: each identified value prints at most the significant digits
    its interval supports (contactid.latex.significant_digits; 0 where the value is lost in its interval)."""
    import re

    import pandas as pd
    from contactid.latex import significant_digits

    def digits(cell: str) -> int:
        mantissa = re.match(r"\$(-?[0-9.]+)", cell).group(1).lstrip("-")
        return len(mantissa.replace(".", "").lstrip("0").rstrip("0" if "." not in mantissa else "")) or 0

    for table, value, low, high in (
        ("table3", "identified_n_per_m", "interval_low_n_per_m", "interval_high_n_per_m"),
        ("table4", "identified", "interval_low", "interval_high"),
    ):
        csv = pd.read_csv(default_run / f"results/tables/{table}.csv").set_index("parameter")
        rows = [
            line.split(" & ")
            for line in (default_run / f"results/report/{table}.tex").read_text().splitlines()
            if line.count(" & ") >= 3 and "$" in line
        ]
        assert len(rows) == len(csv), table
        for cells in rows:
            name = cells[0].replace("\\_", "_")
            r = csv.loc[name]
            if cells[1] == "$--$":  # no value: the data bound it from one side only (k_n), the row gives that bound
                assert r["reported_as"] == "lower bound" and np.isnan(r[value]), f"{table} {name}"
                continue
            allowed = significant_digits(float(r[value]), float(r[low]), float(r[high]))
            assert digits(cells[1]) <= max(allowed, 1), f"{table} {name}: {cells[1]} ({allowed} digits supported)"
            if allowed == 0:
                assert cells[1] == "$0$", f"{table} {name}: {cells[1]} is lost in its interval"
    # Table 8 (gap.tex): the friction law's values against their intervals with the model-form term
    intervals = json.loads((default_run / "results/gap/friction_intervals.json").read_text())["parameters"]
    tex = (default_run / "results/report/gap.tex").read_text()
    body = tex[tex.index("tab:intervals") :].split(r"\midrule")[1].split(r"\bottomrule")[0]
    rows = [line.split(" & ") for line in body.strip().splitlines()]
    names = ["e_f", "k_c", "e_t", "kappa", "mu", "e0", "mu_a", "e0_a2"]  # then what the data bind
    assert len(rows) == len(names)
    for name, cells in zip(names, rows):
        v = intervals[name]
        allowed = significant_digits(v["value"], *v["interval"])
        assert digits(cells[1]) <= max(allowed, 1), f"Table 8 {name}: {cells[1]} ({allowed} digits supported)"
        if allowed == 0:
            assert cells[1] == "$0$", f"Table 8 {name}: {cells[1]} is lost in its interval"


def test_a_given_floor_reruns_the_gaps_jobs_without_the_floors(default_run, tmp_path):
    """gap.measure_floor false (min_gap as given): the floor's rule is left out; the diagnosis and the friction
    intervals run again, nothing upstream of them (the model update reads its own block alone)."""
    cfg = yaml.safe_load((default_run / "config" / "config.yaml").read_text())
    cfg["gap"]["measure_floor"] = False
    alt = tmp_path / "given_floor.yaml"  # a dry run: the shared project stays untouched
    alt.write_text(yaml.safe_dump(cfg))
    res = snakemake(default_run, "--configfile", str(alt), "-n", "--quiet", "rules")
    assert res.returncode == 0, res.stderr[-3000:]
    jobs = _planned_jobs(res)
    assert jobs.get("gap_diagnosis") == 1 and jobs.get("friction_intervals") == 1 and "gap_floor" not in jobs
    assert "friction_fit" not in jobs and "model_updating" not in jobs and "rig_dual_sine" not in jobs
    assert (default_run / "results" / "gap" / "floor.json").exists()  # the default run measured it
