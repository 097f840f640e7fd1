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
