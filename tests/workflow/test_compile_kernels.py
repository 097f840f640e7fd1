"""`contactid compile-kernels` (make env runs it) against the acceptance run: the workflow's jobs find every kernel
signature they use compiled (the kernels' cache itself: tests/test_numba_cache.py)."""

import subprocess
import sys
from pathlib import Path

import pytest
from contactid.io import package_digest
from workflow_projects import repository_kernels


def cached_signatures(cache: Path) -> set:
    """(kernel file, signature) of every compiled kernel under numba cache directory ``cache``, read from numba's
    index files (*.nbi: a pickled format version, then the pickled (source stamp, {(signature, target): file}))."""
    import pickle

    found = set()
    for index in cache.rglob("*.nbi"):
        with open(index, "rb") as fh:
            pickle.load(fh)
            _, overloads = pickle.loads(fh.read())
        found |= {(index.name, str(key[0])) for key in overloads}
    return found


@pytest.mark.workflow
def test_compile_kernels_leaves_the_workflows_jobs_nothing_to_compile(default_run, tmp_path):
    """`contactid compile-kernels` (make env runs it) compiles every kernel signature the acceptance run's jobs
    compiled (the default target: rig, fit, harmonic balance, every gap candidate); one it missed the first run's jobs
    would compile. (The small run's gap diagnosis tries fewer candidates: harmonic balance with Iwan's sliders, for
    one, is not among its signatures.)

    Its cache is the repository's, where make env compiled this code's kernels (in a fresh clone, as CI's, nothing
    else has written there; the runs started from copies of it), else one it compiles now."""
    digest = package_digest()
    cache = repository_kernels()
    if not cache.is_dir():
        cache = tmp_path / "cache"
        out = subprocess.run(
            [sys.executable, "-m", "contactid", "compile-kernels", "config/config.yaml", "--cache", str(cache)],
            cwd=default_run,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert out.returncode == 0 and "not compiled ahead" not in out.stdout, out.stdout + out.stderr
    ours, workflows = cached_signatures(cache), cached_signatures(default_run / ".snakemake" / "numba-cache" / digest)
    assert len(workflows) >= 25  # the rig's integrator and its callees, the fit's population, harmonic balance
    assert workflows <= ours, sorted(workflows - ours)
