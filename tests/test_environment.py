from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def test_every_requirement_is_pinned_and_mirrored_in_the_conda_env():
    reqs = [
        line.strip()
        for line in (ROOT / "requirements.txt").read_text().splitlines()
        if line.strip() and not line.startswith("#")
    ]
    assert reqs and all("==" in r for r in reqs)
    env = yaml.safe_load((ROOT / "workflow" / "envs" / "contactid.yaml").read_text())
    pip = next(d["pip"] for d in env["dependencies"] if isinstance(d, dict))
    assert sorted(pip) == sorted(reqs)


def test_stop_slurm_stops_only_the_daemons_start_slurm_recorded(tmp_path):
    """.ci/slurm/stop-slurm ends the pids start-slurm listed, and only while they run the listed program: another
    process (another cluster's daemon, or a pid reused by another program) is left alone."""
    import os
    import subprocess

    script = Path(__file__).resolve().parents[1] / ".ci/slurm/stop-slurm"
    ours, other = (subprocess.Popen(["sleep", "60"]) for _ in range(2))
    reused = subprocess.Popen(["sleep", "60"])  # listed under another program's name: a reused pid
    try:
        (tmp_path / "pids").write_text(f"sleep {ours.pid}\nslurmd {reused.pid}\n")
        env = {**os.environ, "CONTACTID_SLURM_RUN": str(tmp_path)}
        out = subprocess.run(["bash", str(script)], env=env, capture_output=True, text=True, timeout=30)
        assert out.returncode == 0 and "SLURM stopped" in out.stdout
        assert ours.wait(timeout=10) != 0  # ended by a signal
        assert other.poll() is None and reused.poll() is None
        assert not (tmp_path / "pids").exists()
        again = subprocess.run(["bash", str(script)], env=env, capture_output=True, text=True, timeout=30)
        assert again.returncode == 0 and "nothing stopped" in again.stdout
    finally:
        for p in (ours, other, reused):
            p.kill()
            p.wait()


def test_the_python_code_is_formatted_and_passes_the_linter():
    """`ruff format --check` and `ruff check` (pyproject.toml: line length 120, pycodestyle, pyflakes, and no noqa
    that suppresses nothing) over the package, the rule scripts, the tests and the benchmarks."""
    import subprocess
    import sys

    for args in (["format", "--check"], ["check"]):
        out = subprocess.run([sys.executable, "-m", "ruff", *args, "."], cwd=ROOT, capture_output=True, text=True)
        assert out.returncode == 0, f"ruff {' '.join(args)}:\n{out.stdout[-3000:]}{out.stderr[-1000:]}"
