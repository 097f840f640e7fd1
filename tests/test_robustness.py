"""The workflow survives interruption: a run killed in the rig or in the friction fit resumes with
``snakemake --rerun-incomplete`` to results bit-identical to an uninterrupted run made at the same
time in another directory; outputs are written whole or not at all."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from contactid.io import write_dataset
from test_workflow import make_project

TARGET = "results/friction/friction_fit.nc"


def _start(proj: Path, *args) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(proj / "workflow"), "NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    # as from a terminal: a run started in the background (CI, nohup ... &) inherits SIGINT ignored, and
    # Python then never turns Ctrl-C into KeyboardInterrupt; restore the default disposition
    return subprocess.Popen([sys.executable, "-m", "snakemake", "--cores", "1", *args], cwd=proj, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _finish(p: subprocess.Popen, timeout=900) -> str:
    out, _ = p.communicate(timeout=timeout)
    assert p.returncode == 0, out[-3000:]
    return out


def _job_running(proj: Path, rule: str) -> bool:
    """Is the Python process of ``rule``'s script (written by Snakemake into proj/.snakemake/scripts) running?"""
    mark = f"{proj}/.snakemake/scripts/"
    for cmd in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            text = cmd.read_bytes().decode(errors="replace")
        except OSError:
            continue
        if mark in text and f".{rule}.py" in text:
            return True
    return False


def _interrupt_during(p: subprocess.Popen, proj: Path, rule: str, sig, timeout=600) -> str:
    """Send ``sig`` to the whole run (snakemake and its job) while ``rule``'s script is running; its output."""
    t0 = time.time()
    while not _job_running(proj, rule):
        assert p.poll() is None, "the run ended before the job to interrupt started"
        assert time.time() - t0 < timeout, f"{rule} never started"
        time.sleep(0.05)
    time.sleep(1.0)  # inside the job's computation
    assert _job_running(proj, rule), f"{rule} ended within a second; nothing was interrupted"
    os.killpg(p.pid, sig)
    out, _ = p.communicate(timeout=120)
    return out


def _datasets(proj: Path) -> dict:
    return {str(f.relative_to(proj)): f for d in ("data", "results") for f in sorted((proj / d).rglob("*.nc"))}


@pytest.mark.workflow
def test_killed_runs_resume_to_bit_identical_results(tmp_path):
    (tmp_path / "reference").mkdir()
    (tmp_path / "interrupted").mkdir()
    ref, run = make_project(tmp_path / "reference"), make_project(tmp_path / "interrupted")
    reference = _start(ref, TARGET)  # uninterrupted, at the same time in another directory
    # 1. SIGKILL in the middle of the rig (no chance to clean up: the lock and the incomplete marker stay)
    first = _start(run, TARGET)
    _interrupt_during(first, run, "rig_dual_sine", signal.SIGKILL)
    for f in _datasets(run).values():  # whatever exists is whole: it loads
        xr.load_dataset(f, engine="netcdf4")
    _finish(_start(run, "--unlock"))
    # 2. resume, then SIGINT in the middle of the friction fit
    second = _start(run, "--rerun-incomplete", TARGET)
    out = _interrupt_during(second, run, "friction_fit", signal.SIGINT)
    assert not (run / TARGET).exists(), out[-3000:]  # the interrupted job left no output
    # 3. resume to the end
    _finish(_start(run, "--rerun-incomplete", TARGET))
    _finish(reference)
    a, b = _datasets(ref), _datasets(run)
    assert set(a) == set(b) and TARGET in a
    for name in a:
        x, y = xr.load_dataset(a[name], engine="netcdf4"), xr.load_dataset(b[name], engine="netcdf4")
        assert x.attrs["content_sha256"] == y.attrs["content_sha256"], name
        for v in x.data_vars:
            np.testing.assert_array_equal(x[v].values, y[v].values, err_msg=f"{name}:{v}")


def test_a_failed_write_leaves_the_previous_file_untouched(tmp_path, monkeypatch):
    path = tmp_path / "out.nc"
    good = xr.Dataset({"x": ("i", np.arange(4.0), {"units": "1", "long_name": "x"})})
    write_dataset(good, path)
    before = path.read_bytes()

    def broken(self, target, *a, **k):
        Path(target).write_bytes(b"CDF\x01 half a file")
        raise OSError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", broken)
    with pytest.raises(OSError, match="disk full"):
        write_dataset(good.assign(x=good["x"] * 2), path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["out.nc"]  # no temporary file left behind
