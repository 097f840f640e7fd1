"""Project directories for the workflow's integration tests, and Snakemake runs in them.

A project is a copy of the Snakefile, workflow/ and paper/ with its own config/config.yaml: the default
config (config/config.yaml, the acceptance run) or the small integration config (.test/config_small.yaml,
shorter records, a small GA, fewer gap candidates), with dotted-key overrides. A test that changes a
project which other tests read works on a ``copy_project`` of it.

The runs the tests read (the shared small run, the acceptance run on the default config, and the small-config
projects below, ``prepare_*``) start in the background as soon as pytest knows that a selected test needs
them (conftest.py's SHARED_RUNS), so that they run while other tests do; ``BackgroundRun.wait`` is where a
test first needs the results.

numba compiles the package's kernels once per project (its cache, .snakemake/numba-cache/<code digest>/,
is keyed by the sources' absolute directories): tens of seconds of CPU per project. A project gets compiled
kernels (``seed_kernels``): those `make env` compiled in the repository (``contactid compile-kernels``), and once
the shared small run has finished, that run's, so that no project compiles what another has; the workflow's own
results do not depend on it.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_CONFIG = ROOT / "config" / "config.yaml"
SMALL_CONFIG = ROOT / ".test" / "config_small.yaml"


def set_dotted(cfg: dict, dotted: str, value) -> None:
    """cfg["a"]["b"]["c"] = value for dotted = "a.b.c"."""
    d = cfg
    *head, last = dotted.split(".")
    for k in head:
        d = d[k]
    d[last] = value


# the run whose compiled kernels new projects get once it has finished (conftest.py: the shared small run)
KERNEL_DONOR: "BackgroundRun | None" = None


def repository_kernels() -> Path:
    """The repository's numba cache for its code (.snakemake/numba-cache/<code digest>): where `make env` compiled the
    kernels (``contactid compile-kernels``) and the workflow run in the repository caches them; it may not exist."""
    return ROOT / ".snakemake" / "numba-cache" / code_digest(ROOT / "workflow" / "contactid")


def kernel_donor() -> Path | None:
    """KERNEL_DONOR's project if its run has finished successfully (never waits), else the repository itself
    where kernels of this code were compiled (``repository_kernels``), else None."""
    run = KERNEL_DONOR
    if run is not None and run.proc is not None and run.proc.poll() == 0:
        return run.proj
    if repository_kernels().is_dir():
        return ROOT
    return None


def code_digest(package: Path) -> str:
    """The digest contactid.io.package_digest computes for the package directory ``package``."""
    h = hashlib.sha256()
    for path in sorted(Path(package).rglob("*.py")):
        h.update(str(path.relative_to(package)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _kernel_dir(proj: Path, digest: str, package_dir: Path) -> Path:
    """Where numba caches the kernels of the sources in ``package_dir`` for a run in ``proj`` (the Snakefile's
    NUMBA_CACHE_DIR, .snakemake/numba-cache/<digest>, and numba's subdirectory for that source directory)."""
    from numba.core.caching import _CacheLocator  # the subdirectory numba's NUMBA_CACHE_DIR locator uses

    return (
        proj
        / ".snakemake"
        / "numba-cache"
        / digest
        / _CacheLocator.get_suitable_cache_subpath(str(package_dir / "_.py"))
    )


def seed_kernels(proj: Path, donor: Path | None = None) -> int:
    """Copy the compiled kernels of ``donor`` (default KERNEL_DONOR), a project of the same code that has run,
    into ``proj``'s cache, under ``proj``'s source directories; numba loads them when the source files' sizes
    and modification times match (the projects' copies keep the repository's). Each source directory's
    cache is copied whole, from one donor, into an empty place (numba's index names its compiled files).
    Returns the number of directories copied."""
    donor = donor or kernel_donor()
    if donor is None:
        return 0
    proj, donor = Path(proj).resolve(), Path(donor).resolve()
    digest = code_digest(proj / "workflow" / "contactid")
    if digest != code_digest(donor / "workflow" / "contactid"):
        return 0  # other code: its kernels would not load
    made = [d.name for d in (donor / ".snakemake" / "numba-cache").glob("*") if d.is_dir()]
    if digest not in made and len(made) == 1:
        digest = made[0]  # the workflow names its cache otherwise; the donor's only one is the same code's
    copied = 0
    for package_dir in sorted({p.parent for p in (donor / "workflow" / "contactid").rglob("*.py")}):
        src = _kernel_dir(donor, digest, package_dir)
        dst = _kernel_dir(proj, digest, proj / package_dir.relative_to(donor))
        if src.is_dir() and not dst.exists():
            shutil.copytree(src, dst)
            copied += 1
    return copied


def make_project(tmp: Path, overrides: dict | None = None, config: Path = DEFAULT_CONFIG) -> Path:
    """A project in ``tmp`` on ``config`` (default: config/config.yaml) with dotted-key ``overrides``,
    with KERNEL_DONOR's compiled kernels when there is one."""
    tmp = Path(tmp)
    shutil.copy(ROOT / "Snakefile", tmp / "Snakefile")
    shutil.copytree(ROOT / "workflow", tmp / "workflow", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    shutil.copytree(ROOT / "paper", tmp / "paper")
    (tmp / "config").mkdir()
    cfg = yaml.safe_load(Path(config).read_text())
    # the blind gap benchmark (about 45 min) stays out of the tests' report; tests/gap/test_gap.py checks the diagnosis
    cfg["gap_benchmark"]["in_report"] = False
    # the 30-job study likewise; tests/workflow/test_noise_study.py runs a small one
    cfg["noise_study"]["in_report"] = False
    for dotted, value in (overrides or {}).items():
        set_dotted(cfg, dotted, value)
    (tmp / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
    seed_kernels(tmp)
    return tmp


# what the tests on the small config read from the shared small run: every record, the chain up to every
# case's contact forces, the friction fit and the gap diagnosis (not the outputs for people: figures, tables,
# report; the acceptance run makes those, and the tests of them use it)
SMALL_RUN_TARGETS = (
    "rig",
    "results/friction/friction_fit.nc",
    "results/gap/diagnosis.json",
    *[f"results/{c}/contact_forces.nc" for c in ("lc1", "lc2", "lc3")],
)


def small_project(tmp: Path, overrides: dict | None = None) -> Path:
    """A project on the small integration config .test/config_small.yaml."""
    return make_project(tmp, overrides, SMALL_CONFIG)


def project_config(proj: Path) -> dict:
    return yaml.safe_load((Path(proj) / "config" / "config.yaml").read_text())


def copy_project(src: Path, dst: Path) -> Path:
    """A copy of a project that has run: workflow, config, records, results, logs and Snakemake's metadata,
    with their modification times (so that Snakemake sees the copy as up to date), for a test that changes
    files, config or code: the shared project stays as the other tests expect it."""
    shutil.copytree(src, dst, symlinks=True, ignore=shutil.ignore_patterns("locks", "__pycache__", "numba-cache"))
    seed_kernels(dst, src)  # its kernels, under the copy's own source directories
    return Path(dst)


def snakemake_env(cwd: Path) -> dict:
    return {**os.environ, "PYTHONPATH": str(Path(cwd) / "workflow")}


def snakemake(cwd: Path, *args, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "snakemake", "--cores", "2", *args],
        cwd=cwd,
        env=snakemake_env(cwd),
        capture_output=True,
        text=True,
        timeout=timeout,
    )


class BackgroundRun:
    """A project and ``snakemake --cores 2 [targets]`` in it, in the background: ``prepare(directory)`` makes the
    project in an empty directory and returns (project, targets). Both happen now, or, given ``after`` (another
    BackgroundRun), once that one has ended (the project then gets its compiled kernels if it succeeded), in a
    thread. ``nice`` lowers the run's CPU priority (a run the tests need later yields to those needed sooner);
    the run stays in pytest's session (a process group of its own), where the kernel's autogroup scheduling
    lets nice values count (a new session would get an equal share of the CPU whatever its nice value).
    ``wait()`` returns the project once the run has finished, and fails the calling test with the end of the
    run's output if the project could not be made or the run failed."""

    def __init__(self, base: Path, prepare, after: "BackgroundRun | None" = None, nice: int = 0, timeout: float = 1800):
        self.base = Path(base)
        self.log = self.base / "snakemake.log"
        self.proj: Path | None = None
        self.targets: tuple = ()
        self.nice = int(nice)
        self.timeout = timeout
        self.started = time.time()
        self.proc: subprocess.Popen | None = None
        self._error: BaseException | None = None
        self._stopped = False
        self._lock = threading.Lock()
        self._thread = None
        if after is None:
            self._prepare_and_start(prepare, None)
        else:
            self._thread = threading.Thread(target=self._prepare_and_start, args=(prepare, after), daemon=True)
            self._thread.start()

    def _prepare_and_start(self, prepare, after: "BackgroundRun | None") -> None:
        try:
            if after is not None and after._thread is not None:
                after._thread.join()  # a run that itself follows another has started (or failed to) by then
            if after is not None and after.proc is not None:
                after.proc.wait()
            (self.base / "project").mkdir()
            proj, targets = prepare(self.base / "project")
            if after is not None and after.proc is not None and after.proc.returncode == 0:
                seed_kernels(proj, after.proj)
            self.proj, self.targets = Path(proj), tuple(targets)
            with self._lock:
                if self._stopped:
                    return
                nice = self.nice
                with open(self.log, "w") as out:
                    self.proc = subprocess.Popen(
                        [sys.executable, "-m", "snakemake", "--cores", "2", *self.targets],
                        cwd=self.proj,
                        env=snakemake_env(self.proj),
                        stdout=out,
                        stderr=subprocess.STDOUT,
                        process_group=0,
                        preexec_fn=(lambda: os.nice(nice)) if nice else None,
                    )
        except BaseException as exc:  # reported by wait(), in the test that needs the run
            self._error = exc

    def output(self) -> str:
        """What snakemake printed (stdout and stderr)."""
        return self.log.read_text(errors="replace") if self.log.exists() else ""

    def wait(self) -> Path:
        left = lambda: max(1.0, self.timeout - (time.time() - self.started))  # noqa: E731
        if self._thread is not None:
            self._thread.join(timeout=left())
        if self._error is not None:
            raise AssertionError(f"the project in {self.base} could not be made: {self._error!r}") from self._error
        if self.proc is None:
            raise AssertionError(f"snakemake in {self.base} did not start")
        try:
            rc = self.proc.wait(timeout=left())
        except subprocess.TimeoutExpired:
            self.stop()
            raise AssertionError(f"snakemake in {self.proj} did not finish within {self.timeout:.0f} s")
        assert rc == 0, f"snakemake {' '.join(self.targets)} in {self.proj} failed:\n" + self.output()[-3000:]
        return self.proj

    def stop(self) -> None:
        """End the run if it is still going (the session ends first): its own process group only."""
        with self._lock:
            self._stopped = True
            proc = self.proc
        if proc is not None and proc.poll() is None:
            os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)


# ------------------------------------------------------------------------------------------------
# the projects the integration tests read, made and run in the background (conftest.py): each is
# prepare(directory) -> (project, targets); those on the small config run after the small run
# ------------------------------------------------------------------------------------------------


def prepare_small_run(d: Path):
    return small_project(d), SMALL_RUN_TARGETS


def prepare_default_run(d: Path):
    return make_project(d), ()  # the default target: the whole workflow


TWO_CASES = {
    "load_cases": {"lc1": {"A1_m_per_s2": 14.0, "A2_m_per_s2": 34.0}, "lc3": {"A1_m_per_s2": 20.0, "A2_m_per_s2": 50.0}}
}


def prepare_rig_run(d: Path):
    """The rig target alone, on the small config with two of its three load cases (the small run's seed)."""
    return small_project(d, TWO_CASES), ("rig",)


def prepare_other_seed_run(d: Path):
    """lc1's rig record on the small config with another seed (1234)."""
    return small_project(d, {"seed": 1234}), ("data/raw/lc1.nc",)


SWEEP = {"noise_study": {"noise_fractions": [0.001, 0.05], "record_samples": [8192], "seeds": [1], "in_report": False}}


def prepare_noise_sweep_run(d: Path):
    """A two-point noise study on the small config (the points' random test is its 51.2 s record, the
    dual-sine length the study's)."""
    return small_project(d, SWEEP), ("noise_study",)


FRF_FILE_TARGETS = (
    "results/linear/stiction.nc",
    "results/linear/frf_measured.uff",
    "results/linear/frf_synthesised.uff",
)


NUMBERS = "results/report/numbers.tex"  # the numbers the PDF prints (\\input by paper/report.tex)


def prepare_lower_confidence_run(d: Path, default_run: Path):
    """A copy of the acceptance run with a fit setting whose effect reaches the PDF's numbers for sure, the
    friction intervals' confidence level (0.9; fewer GA generations no longer do: the polish after the GA lands
    on the same optimum to the digits printed), given by --configfile; the target is the PDF's numbers."""
    proj = copy_project(default_run, d / "copy")
    cfg = project_config(proj)
    cfg["friction"]["confidence"] = 0.9
    alt = d / "lower_confidence.yaml"
    alt.write_text(yaml.safe_dump(cfg))
    return proj, (NUMBERS, "--configfile", str(alt))  # (--configfile takes every argument after it)


MEASURED_FORMATS = {
    "lc1": ("uff58", {"acceleration": ("g", None, None)}),
    "lc2": ("tdms", {"force": ("mV", 2.25, "mV/N"), "acceleration": ("mV", 10.2, "mV/g")}),
    "lc3": ("csv", None),
}


def prepare_measured_run(d: Path, small_run: Path):
    """A project whose every record is a measured file, none from the rig: the small run's random test as its FRFs
    in a UFF58 file (function types 4 and 6, as labs hand them over), and its three load cases' records written as
    a UFF58 file (lc1, accelerations in g), a TDMS file (lc2, voltages with sensitivities) and a CSV + sidecar YAML
    (lc3); the gap target (one candidate), every case's contact forces, the FRFs written back out
    (frf_measured.uff, frf_synthesised.uff) and the report (no truth anywhere), from these files alone. The files
    are written in a process of their own (``write_measured_files``): this runs in a background thread of the pytest
    process, and HDF5 (netCDF4) is not thread-safe while the tests read and write netCDF files (a Bus error, seen
    once)."""
    proj = small_project(d, {"gap.candidates": ["viscous_friction"]})
    code = "import sys, pathlib, workflow_projects as wp; wp.write_measured_files(*map(pathlib.Path, sys.argv[1:]))"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "workflow"), str(ROOT / "tests")])}
    subprocess.run([sys.executable, "-c", code, str(proj), str(small_run)], check=True, env=env)
    return proj, (
        "gap",
        *[f"results/{c}/contact_forces.nc" for c in MEASURED_FORMATS],
        *FRF_FILE_TARGETS[1:],
        "results/report/report.pdf",
    )


def write_measured_files(proj: Path, small_run: Path) -> None:
    """The measured run's files (``prepare_measured_run``) and its config."""
    import xarray as xr
    from contactid.importers.export import export_record
    from contactid.importers.frf_export import write_frf_uff58
    from contactid.linear_chain import complex_frf

    (proj / "measured").mkdir()
    frf = xr.load_dataset(small_run / "results/linear/frf.nc", engine="netcdf4")
    block = write_frf_uff58(
        proj / "measured/frf.uff", frf["frequency"].values, complex_frf(frf), frf["sensor"].values, frf["coherence"]
    )
    cfg = project_config(proj)
    cfg["random_test"] = {**block, "file": "measured/frf.uff"}
    cfg["load_cases"] = {}
    for case, (fmt, storage) in MEASURED_FORMATS.items():
        raw = xr.load_dataset(small_run / f"data/raw/{case}.nc", engine="netcdf4")
        block = export_record(raw, proj / "measured" / f"{case}.{fmt}", fmt, storage)
        block["file"] = f"measured/{case}.{fmt}"
        cfg["load_cases"][case] = block
    (proj / "config" / "config.yaml").write_text(yaml.safe_dump(cfg))
