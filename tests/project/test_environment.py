from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]


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
    # the package's own dependencies (pyproject.toml) at the same pins
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["dependencies"] and set(project["dependencies"]) <= set(reqs)
    assert project["scripts"]["contactid"] == "contactid.__main__:main"


def test_the_command_line_documents_itself(tmp_path):
    """`python -m contactid --help` prints the subcommands to stdout and exits 0; `check-config` passes the
    shipped configs and names the key of a bad one."""
    import subprocess
    import sys

    def run(*args):
        return subprocess.run([sys.executable, "-m", "contactid", *args], cwd=ROOT, capture_output=True, text=True)

    out = run("--help")
    assert out.returncode == 0 and "audit" in out.stdout and "check-config" in out.stdout
    for command in ("check-config", "compile-kernels"):  # the docstring's prose, not its numpydoc sections
        out = run(command, "--help")
        assert out.returncode == 0 and ("Validate a config" in out.stdout or command != "check-config")
        assert "Parameters" not in out.stdout and "Returns" not in out.stdout and "----" not in out.stdout
    for cfg in ("config/config.yaml", ".test/config_small.yaml"):
        assert run("check-config", cfg).returncode == 0
    bad = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    bad["frf"]["segmnt_length"] = 8192
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump(bad))
    out = run("check-config", str(tmp_path / "bad.yaml"))
    assert out.returncode == 1 and "frf: Additional properties are not allowed ('segmnt_length'" in out.stdout


def test_stop_slurm_stops_only_the_daemons_start_slurm_recorded(tmp_path):
    """.ci/slurm/stop-slurm ends the pids start-slurm listed, and only while they run the listed program: another
    process (another cluster's daemon, or a pid reused by another program) is left alone."""
    import os
    import subprocess

    script = Path(__file__).resolve().parents[2] / ".ci/slurm/stop-slurm"
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


def test_the_package_keeps_its_layers_and_no_cycle():
    """import-linter's contracts (pyproject.toml, [tool.importlinter]): the package's layers, deferred imports
    included, and no cycle among the modules of a subpackage."""
    import subprocess
    import sys

    out = subprocess.run(
        [Path(sys.executable).parent / "lint-imports", "--no-cache"], cwd=ROOT, capture_output=True, text=True
    )
    assert out.returncode == 0, f"lint-imports:\n{out.stdout[-4000:]}{out.stderr[-1000:]}"


@pytest.mark.slow
def test_the_workflow_is_formatted_linted_and_documents_every_rule():
    """`snakefmt --no-sort --check` (pyproject.toml: line length 120) and `snakemake --lint` clean over the
    Snakefile and workflow/rules; every rule opens with a docstring, the sentence `snakemake --list-rules` prints."""
    import re
    import subprocess
    import sys

    smk = [ROOT / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]
    bin_dir = Path(sys.executable).parent
    out = subprocess.run([bin_dir / "snakefmt", "--no-sort", "--check", *smk], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, (
        f"snakefmt --check (run `snakefmt --no-sort Snakefile workflow/rules`):\n{out.stderr[-3000:]}"
    )
    lint = subprocess.run([sys.executable, "-m", "snakemake", "--lint"], cwd=ROOT, capture_output=True, text=True)
    assert lint.returncode == 0 and "good condition" in lint.stdout + lint.stderr, (lint.stdout + lint.stderr)[-3000:]
    for path in smk:
        lines = path.read_text().splitlines()
        for i, line in enumerate(lines):
            if re.match(r"^\s*(local)?rule( \w+)?:\s*$", line):
                assert lines[i + 1].strip().startswith('"""'), f"{path.name}: {line.strip()} has no docstring"


def test_licence_and_citation_are_present():
    """A permissive licence (MIT, as pyproject.toml declares) and a CITATION.cff with the fields CFF 1.2.0
    requires (`cffconvert --validate` passes it), citing the paper the workflow reproduces."""
    import tomllib

    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    assert tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"] == "MIT"
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0" and cff["message"] and cff["title"] and cff["authors"]
    (paper,) = cff["references"]
    assert paper["journal"] == "Journal of Sound and Vibration" and paper["year"] == 2012
    assert [a["family-names"] for a in paper["authors"]] == ["Pourahmadian", "Ahmadian", "Jalali"]
