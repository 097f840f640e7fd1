"""numba's compiled kernels are cached in a directory named by the package's code digest: a new
process loads them instead of compiling, and a changed kernel, or a kernel whose callee in another
module changed (numba's own check reads only the kernel's file), is never served stale."""

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import contactid
import pytest
from contactid import numba_cache_dir
from contactid.io import package_digest

PACKAGE = Path(contactid.__file__).resolve().parent

CALLEE = "from numba import njit\n\n\n@njit(cache=True)\ndef value():\n    return {value}\n"
CALLER = (
    "from numba import njit\n\nfrom .probe_callee import value\n\n\n"
    "@njit(cache=True)\ndef call():\n    return value()\n"
)
RUN = """
import json, os, {pkg}.probe_caller as m
result = m.call()
print(json.dumps({{"result": result, "cache_dir": os.environ.get("NUMBA_CACHE_DIR"),
                   "loaded": sum(m.call.stats.cache_hits.values()),
                   "compiled": sum(m.call.stats.cache_misses.values())}}))
"""


def run(pkg: str, pythonpath: Path, cache_dir: Path) -> dict:
    env = {
        **os.environ,
        "PYTHONPATH": str(pythonpath),
        "NUMBA_CACHE_DIR": str(cache_dir),
        "PYTHONDONTWRITEBYTECODE": "1",
    }
    out = subprocess.run(
        [sys.executable, "-c", RUN.format(pkg=pkg)],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        cwd=pythonpath,
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_digest_matches_the_workflows_and_names_the_cache_directory():
    # sha256 over the sources' relative paths and bytes, in sorted order, computed here independently
    h = hashlib.sha256()
    root = Path(contactid.__file__).resolve().parent
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    assert package_digest() == contactid.code_digest() == h.hexdigest()[:16]
    assert Path(contactid.NUMBA_CACHE_DIR).name == package_digest()
    assert os.environ["NUMBA_CACHE_DIR"] == contactid.NUMBA_CACHE_DIR


def test_cache_directory_always_ends_in_the_current_digest(tmp_path, monkeypatch):
    d = "0123456789abcdef"
    snakefile = tmp_path / ".snakemake" / "numba-cache"
    assert numba_cache_dir(str(snakefile / d), d) == snakefile / d  # the Snakefile's: kept
    assert numba_cache_dir(str(snakefile / "fedcba9876543210"), d) == snakefile / d  # set before the code changed
    assert numba_cache_dir(str(tmp_path / "mine"), d) == tmp_path / "mine" / d  # a user's own directory
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert numba_cache_dir("", d) == tmp_path / "xdg" / "contactid" / "numba-cache" / d  # unset


@pytest.mark.slow
def test_changed_callee_is_compiled_afresh_not_served_stale(tmp_path):
    # a copy of the package with a kernel that calls a kernel from another module
    pkgs = tmp_path / "pkgs"
    pkg = pkgs / "contactid"
    shutil.copytree(PACKAGE, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    (pkg / "probe_callee.py").write_text(CALLEE.format(value="1.0"))
    (pkg / "probe_caller.py").write_text(CALLER)
    snakefile_dir = tmp_path / ".snakemake" / "numba-cache"
    # a directory named by another code's digest: the package swaps in its own
    first = run("contactid", pkgs, snakefile_dir / "0000000000000000")
    old = Path(first["cache_dir"]).name
    assert first["result"] == 1.0 and first["compiled"] == 1
    assert Path(first["cache_dir"]) == snakefile_dir / old and old != "0000000000000000"
    # a new process with the directory the Snakefile sets for this code: loaded, not compiled
    second = run("contactid", pkgs, snakefile_dir / old)
    assert second == {**first, "loaded": 1, "compiled": 0}

    # the callee changes (another module than the caller's); the job still has the old directory
    (pkg / "probe_callee.py").write_text(CALLEE.format(value="20.0"))
    third = run("contactid", pkgs, snakefile_dir / old)
    new = Path(third["cache_dir"]).name
    assert new != old and Path(third["cache_dir"]) == snakefile_dir / new
    assert third["result"] == 20.0 and third["compiled"] == 1 and third["loaded"] == 0
    fourth = run("contactid", pkgs, snakefile_dir / new)
    assert fourth["result"] == 20.0 and fourth["loaded"] == 1


@pytest.mark.slow
def test_plain_numba_cache_serves_a_changed_callee_stale(tmp_path):
    """Why the directory is keyed by the digest: with numba's own check alone, the caller's cached
    machine code keeps the callee it was compiled with. (Should this start failing, numba has learned
    to notice changed callees.)"""
    pkg = tmp_path / "plainprobe"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "probe_callee.py").write_text(CALLEE.format(value="1.0"))
    (pkg / "probe_caller.py").write_text(CALLER)
    cache = tmp_path / "cache"
    assert run("plainprobe", tmp_path, cache)["result"] == 1.0
    (pkg / "probe_callee.py").write_text(CALLEE.format(value="20.0"))
    stale = run("plainprobe", tmp_path, cache)
    assert stale["result"] == 1.0 and stale["loaded"] == 1
