"""Benchmark: wall time of the linear chain, rig included, from a clean project copy.

Goal (issue 2): under 60 s on the 2-core machine. Prints the time of the
workflow run and, as a plain baseline in the same process, the time of one
dense generalized eigen-solution of the rig's FE model repeated as often as
the stiffness fit evaluates it, so machine speed can be factored out.

Usage: .venv/bin/python benchmarks/linear_chain.py
"""

import sys
import time
from pathlib import Path

import scipy.linalg

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))

import yaml  # noqa: E402
from contactid.beam_model import assemble  # noqa: E402
from contactid.config import with_defaults  # noqa: E402
from contactid.parameters import structure_from_config  # noqa: E402

sys.path.insert(0, str(ROOT / "benchmarks"))
from common import timed_clean_run  # noqa: E402


def main():
    wall = timed_clean_run(
        "results/linear/linear_modes.nc",
        "results/figures/fig03_frf.png",
        "results/tables/table1.csv",
        "results/tables/paper_consistency.csv",
    )
    cfg = with_defaults(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()))
    m = assemble(structure_from_config(cfg["structure"], 3.95e6, 2.37e7))  # k_t, k_n: Table 3
    t0 = time.perf_counter()
    for _ in range(500):
        scipy.linalg.eigh(m.stiffness, m.mass)
    base = time.perf_counter() - t0
    print(f"linear chain (rig -> FRF -> modal -> stiction -> modes, tables, fig03): {wall:.1f} s (goal < 60 s)")
    print(f"baseline: 500 dense eigen-solutions of the FE model: {base:.2f} s; ratio {wall / base:.1f}")


if __name__ == "__main__":
    main()
