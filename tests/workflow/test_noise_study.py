"""The noise / record-length study as Snakemake jobs: the sweep runs one job per point, and the profiles plan it
(the study's parameter table and e_0 formula: tests/test_studies.py)."""

import json
import shutil
from pathlib import Path

import pytest
import xarray as xr
import yaml
from workflow_projects import make_project, snakemake


@pytest.mark.workflow
def test_sweep_runs_one_job_per_point_and_errors_grow_with_noise(noise_sweep_run):
    # `snakemake noise_study` on the small config with two noise levels, one record length and one seed
    # (workflow_projects.prepare_noise_sweep_run; the points' random test is the small config's 51.2 s record)
    proj = noise_sweep_run
    points = sorted((proj / "results/studies/noise").glob("*.json"))
    assert [p.name for p in points] == [
        "noise_fraction~0.001_record_samples~8192_seed~1.json",
        "noise_fraction~0.05_record_samples~8192_seed~1.json",
    ]
    ds = xr.load_dataset(proj / "results/studies/noise_study.nc", engine="netcdf4")
    assert dict(ds.sizes) == {"noise_fraction": 2, "record_samples": 1, "seed": 1}
    low, high = (json.loads(p.read_text()) for p in points)
    for q in ("mu", "e0", "k_t"):
        assert ds[f"error_{q}"].sel(noise_fraction=0.05).item() == pytest.approx(high[f"error_{q}"])
        assert abs(high[f"error_{q}"]) > abs(low[f"error_{q}"]), q  # ten times... fifty times the noise, larger errors
    assert abs(low["error_mu"]) < 0.02 and abs(low["error_k_t"]) < 1e-3  # near the truth at low noise
    assert (proj / "results/figures/noise_study.png").stat().st_size > 10000
    # the study's jobs declare what a scheduler needs
    cfg = yaml.safe_load((proj / "config/config.yaml").read_text())
    assert cfg["noise_study"]["seeds"] == [1]
    dry = snakemake(proj, "-n", "--forceall", "noise_study")
    assert "noise_study_point" in dry.stdout and "runtime=15" in dry.stdout.replace(" ", "")


@pytest.mark.workflow
@pytest.mark.parametrize("profile", ["default", "slurm"])
def test_profiles_plan_the_sweep_and_comment_every_entry(tmp_path, profile):
    root = Path(__file__).resolve().parents[2]
    proj = make_project(tmp_path)
    shutil.copytree(root / "profiles", proj / "profiles")
    lines = (proj / "profiles" / profile / "config.yaml").read_text().splitlines()
    for i, line in enumerate(lines):  # every top-level entry has a comment line right above it
        if line and not line.startswith((" ", "#")):
            assert lines[i - 1].startswith("#"), f"profiles/{profile}: '{line}' has no comment"
    res = snakemake(proj, "--profile", f"profiles/{profile}", "-n", "noise_study")
    assert res.returncode == 0, res.stderr[-3000:]
    assert "noise_study_point" in res.stdout
