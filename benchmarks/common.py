"""Shared by the benchmarks: run the workflow on a clean copy of the project."""

import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def timed_clean_run(*targets) -> float:
    """Wall time (s) of `snakemake --cores 2 <targets>` in a fresh copy of the project."""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        shutil.copy(ROOT / "Snakefile", tmp)
        for folder in ("workflow", "config", "paper"):
            shutil.copytree(ROOT / folder, tmp / folder, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        t0 = time.perf_counter()
        res = subprocess.run(
            [sys.executable, "-m", "snakemake", "--cores", "2", *targets], cwd=tmp, capture_output=True, text=True
        )
        wall = time.perf_counter() - t0
    if res.returncode:
        print(res.stderr[-2000:])
        raise SystemExit(1)
    return wall


def measured_project(proj: Path, cfg: dict) -> Path:
    """A fresh copy of the project (Snakefile, workflow, paper) in ``proj`` whose config/config.yaml is ``cfg``: the
    benchmarks that read another simulator's records as measured files run the workflow in it."""
    import yaml

    if proj.exists():
        shutil.rmtree(proj)
    proj.mkdir(parents=True)
    shutil.copy(ROOT / "Snakefile", proj / "Snakefile")
    shutil.copytree(ROOT / "workflow", proj / "workflow", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    shutil.copytree(ROOT / "paper", proj / "paper")
    (proj / "config").mkdir()
    (proj / "config" / "config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
    return proj


def run_gap_summary(name: str, proj: Path) -> None:
    """`snakemake -c2 gap summary` in ``proj``; stops the benchmark with the run's output where it fails."""
    print(f"{name}: snakemake gap summary in {proj}", flush=True)
    run = subprocess.run(
        [str(ROOT / ".venv" / "bin" / "snakemake"), "-c2", "gap", "summary"], cwd=proj, capture_output=True, text=True
    )
    if run.returncode:
        print(run.stdout[-3000:], run.stderr[-3000:])
        raise SystemExit(f"{name}: the workflow failed (log in {proj}/.snakemake/log)")
