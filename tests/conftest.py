import os
import sys
from pathlib import Path

import pytest
import yaml

# one BLAS thread per process: the tests' matrices are small, and on a shared 2-core machine OpenBLAS's threads
# oversubscribe the cores (the stiction fit's eigen-solves ran 7x slower); Snakemake runs started by the tests
# inherit it, as two jobs run side by side on --cores 2. A value set by the caller wins.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))
sys.path.insert(0, str(ROOT / "tests"))


def _kernels_for_this_session(compiled: Path) -> str:
    """A numba cache for the kernels the tests run in their own process: a copy of ``compiled``, those `make env`
    compiled for the workflow (contactid compile-kernels, .snakemake/numba-cache/<code digest> in the repository), so
    that they are not compiled again (numba keys a cache by the sources' directory, and a fresh clone's are new), while
    what the tests compile beyond them stays out of the repository's cache (the projects' runs are seeded from it:
    tests/workflow_projects.py). Removed at exit."""
    import atexit
    import shutil
    import tempfile

    tmp = Path(tempfile.mkdtemp(prefix="contactid-test-kernels-"))
    atexit.register(shutil.rmtree, tmp, True)
    shutil.copytree(compiled, tmp / compiled.name)
    return str(tmp / compiled.name)


import workflow_projects as wp  # noqa: E402

# a value set by the caller wins; without kernels compiled for this code (the code changed since make env, and no
# workflow run in the repository has compiled it), the package's own cache (~/.cache/contactid/numba-cache/<digest>),
# which keeps what one session compiles for the next. (workflow_projects imports no kernel module: numba reads the
# variable when a kernel module first imports it.)
if "NUMBA_CACHE_DIR" not in os.environ and (_compiled := wp.repository_kernels()).is_dir():
    os.environ["NUMBA_CACHE_DIR"] = _kernels_for_this_session(_compiled)

# The workflow runs the integration tests read, each in a project of its own (tests/workflow_projects.py):
# name -> (prepare, the run it follows, nice). They start in the background as soon as pytest knows which
# selected tests need them, so that they run while other tests do: the small run first (with the kernels make env
# compiled, it compiles any others once), then the others with its compiled kernels; the acceptance run (the longest
# chain) at normal priority, the short ones at nice 10. Read only: a test that changes a project works on a copy.
SHARED_RUNS = {
    "small_run": (wp.prepare_small_run, None, 0),
    "default_run": (wp.prepare_default_run, "small_run", 0),
    "measured_run": (lambda d: wp.prepare_measured_run(d, _runs["small_run"].proj), "small_run", 10),
    "other_seed_run": (wp.prepare_other_seed_run, "small_run", 10),
    "rig_run": (wp.prepare_rig_run, "small_run", 10),
    "noise_sweep_run": (wp.prepare_noise_sweep_run, "small_run", 10),
    "lower_confidence_run": (lambda d: wp.prepare_lower_confidence_run(d, _runs["default_run"].proj), "default_run", 0),
}
_runs: dict = {}


def _shared_run(config, name: str) -> wp.BackgroundRun:
    if name not in _runs:
        prepare, after, nice = SHARED_RUNS[name]
        _runs[name] = wp.BackgroundRun(config._tmp_path_factory.mktemp(name), prepare, _runs.get(after), nice)
        if name == "small_run":  # projects made after it has finished get its compiled kernels
            wp.KERNEL_DONOR = _runs[name]
    return _runs[name]


# when each run is ready, roughly (the later ones follow the small run and share the machine): a test that reads a run
# waits for it, so the tests are ordered by the latest run they read, the others first; within one rank they keep
# their order. The measured run ends last (about 40 s after the acceptance run in a fresh clone): its tests used to
# wait for it in the middle of tests/workflow/test_workflow.py with every other test of that file still to run
READY_RANK = {
    "small_run": 1,
    "other_seed_run": 2,
    "rig_run": 2,
    "default_run": 3,
    "noise_sweep_run": 3,
    "lower_confidence_run": 4,
    "measured_run": 5,
}


def pytest_collection_modifyitems(session, config, items):
    """Tests that read no shared run first, then by the latest shared run they read (``READY_RANK``)."""
    rank = {id(it): max((READY_RANK.get(f, 0) for f in getattr(it, "fixturenames", ())), default=0) for it in items}
    items.sort(key=lambda it: rank[id(it)])


def pytest_collection_finish(session):
    """Start the runs the selected tests need (in SHARED_RUNS' order: each after the one it follows)."""
    if session.config.option.collectonly:
        return
    needed = {f for item in session.items for f in getattr(item, "fixturenames", ()) if f in SHARED_RUNS}
    for name in SHARED_RUNS:
        if name in needed:
            _shared_run(session.config, name)


def pytest_sessionfinish(session):
    for run in _runs.values():
        run.stop()


def _wait(config, name: str) -> Path:
    return _shared_run(config, name).wait()


@pytest.fixture(scope="session")
def default_config():
    with open(ROOT / "config" / "config.yaml") as fh:
        return yaml.safe_load(fh)


@pytest.fixture(scope="session")
def small_config():
    with open(ROOT / ".test" / "config_small.yaml") as fh:
        return yaml.safe_load(fh)


@pytest.fixture(scope="session")
def default_run(pytestconfig):
    """The acceptance run: the whole workflow on config/config.yaml."""
    return _wait(pytestconfig, "default_run")


@pytest.fixture(scope="session")
def small_run(pytestconfig):
    """The workflow on the small integration config .test/config_small.yaml, up to every case's contact forces,
    the friction fit and the gap diagnosis (workflow_projects.SMALL_RUN_TARGETS)."""
    return _wait(pytestconfig, "small_run")


@pytest.fixture(scope="session")
def measured_run(pytestconfig, small_run):
    """Every record a measured file (the random test as FRFs in a UFF58 file; the load cases as UFF58, TDMS, CSV):
    the gap target, the contact forces and the FRFs written back out (workflow_projects.prepare_measured_run).
    Returns (project, snakemake's output)."""
    proj = _wait(pytestconfig, "measured_run")
    return proj, _runs["measured_run"].output()


@pytest.fixture(scope="session")
def other_seed_run(pytestconfig):
    """lc1's rig record on the small config with seed 1234."""
    return _wait(pytestconfig, "other_seed_run")


@pytest.fixture(scope="session")
def rig_run(pytestconfig):
    """`snakemake rig` on the small config with load cases lc1 and lc3."""
    return _wait(pytestconfig, "rig_run")


@pytest.fixture(scope="session")
def lower_confidence_run(pytestconfig):
    """A copy of the acceptance run, its PDF's numbers made again with friction.confidence 0.9
    (workflow_projects.prepare_lower_confidence_run). Returns (project, snakemake's output)."""
    proj = _wait(pytestconfig, "lower_confidence_run")
    return proj, _runs["lower_confidence_run"].output()


@pytest.fixture(scope="session")
def noise_sweep_run(pytestconfig):
    """`snakemake noise_study` on the small config: two noise levels, one record length, one seed."""
    return _wait(pytestconfig, "noise_sweep_run")
