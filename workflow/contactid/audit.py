"""Audit of the datasets a run left behind: producer, inputs, digests, units, finite values.

`python -m contactid audit results data [--out results/audit.csv]` lists every netCDF dataset
with its producing rule and inputs, recomputes the content digest each dataset stored when it
was written (a mismatch means it was edited afterwards) and the digests of its inputs (a
mismatch means the input changed since: the dataset is stale), and checks every variable for
`units`, `long_name` and finite values (non-finite values are allowed only where the variable
says what they mean, in its `nonfinite_meaning` attribute). Exit status 1 when anything is flagged.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from .io import ENGINE, content_digest, file_digest


def audit_dataset(path: Path, root: Path | None = None) -> dict:
    """Return one row of the audit: the dataset's producer, its inputs and the problems found.

    The stored content digest is recomputed (a mismatch: edited after its rule wrote it), each recorded input's digest
    is compared with the file's (a mismatch: the dataset is stale), and every variable is checked for ``units``,
    ``long_name`` and finite values (unless its ``nonfinite_meaning`` attribute says what they mean).

    Parameters
    ----------
    path
        The netCDF dataset.
    root
        The directory relative input paths are resolved against (the project directory; None: the current one).

    Returns
    -------
    row : dict
        ``dataset`` (the path), ``producer`` (its ``producer_rule``), ``inputs`` (joined by "; "), ``status`` ("ok",
        "flagged" or "unreadable") and ``problems`` (joined by "; "; empty: clean).
    """
    problems = []
    try:
        ds = xr.load_dataset(path, engine=ENGINE)
    except Exception as exc:
        return {"dataset": str(path), "producer": "?", "inputs": "", "status": "unreadable", "problems": str(exc)}
    producer = ds.attrs.get("producer_rule", "")
    if not producer:
        problems.append("no producer_rule attribute")
    stored = ds.attrs.get("content_sha256")
    if stored is None:
        problems.append("no content digest")
    elif content_digest(ds) != stored:
        problems.append("content differs from what its rule wrote (edited by hand?)")
    inputs = []
    for key, value in ds.attrs.items():
        if key.startswith("input_") and not key.endswith("_sha256"):
            inputs.append(str(value))
            digest = ds.attrs.get(f"{key}_sha256")
            where = value if root is None or os.path.isabs(value) else os.path.join(root, value)
            if not os.path.exists(where):
                problems.append(f"input {value} is missing")
            elif digest and file_digest(where) != digest:
                problems.append(f"input {value} changed since this dataset was made (stale)")
    for name, var in ds.data_vars.items():
        for attr in ("units", "long_name"):
            if attr not in var.attrs:
                problems.append(f"{name}: no {attr}")
        values = np.asarray(var.values)
        if values.dtype.kind in "fc" and not np.isfinite(values).all() and "nonfinite_meaning" not in var.attrs:
            problems.append(f"{name}: {int((~np.isfinite(values)).sum())} non-finite values")
    return {
        "dataset": str(path),
        "producer": producer,
        "inputs": "; ".join(inputs),
        "status": "ok" if not problems else "flagged",
        "problems": "; ".join(problems),
    }


def audit(paths: Iterable[str | os.PathLike], root: str | os.PathLike | None = None) -> pd.DataFrame:
    """Audit every netCDF file under ``paths``.

    Parameters
    ----------
    paths
        Directories (searched recursively for ``*.nc``) or files.
    root
        The directory relative input paths are resolved against (the project directory; None: the current one).

    Returns
    -------
    table : pd.DataFrame
        One row per dataset (``audit_dataset``), sorted by path: columns dataset, producer, inputs, status, problems.
    """
    files = sorted({p for top in paths for p in (Path(top).rglob("*.nc") if Path(top).is_dir() else [Path(top)])})
    return pd.DataFrame(
        [audit_dataset(p, None if root is None else Path(root)) for p in files],
        columns=["dataset", "producer", "inputs", "status", "problems"],
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line of ``contactid audit``: print the audit table (and write it to ``--out``).

    Parameters
    ----------
    argv
        The arguments after ``audit``: the paths (default results and data), ``--out`` (a CSV file) and ``--root``
        (the project directory the recorded input paths are relative to); None: ``sys.argv[1:]``.

    Returns
    -------
    status : int
        The exit status: 1 if any dataset is flagged (or unreadable), else 0.
    """
    parser = argparse.ArgumentParser(prog="python -m contactid audit", description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", default=["results", "data"], help="directories or files to audit")
    parser.add_argument("--out", help="write the audit table to this CSV file")
    parser.add_argument("--root", default=".", help="project directory the recorded input paths are relative to")
    args = parser.parse_args(argv)
    table = audit(args.paths, args.root)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        table.to_csv(args.out, index=False)
    with pd.option_context("display.max_colwidth", 120, "display.width", 200):
        print(table[["dataset", "producer", "status", "problems"]].to_string(index=False))
    flagged = int((table["status"] != "ok").sum())
    print(f"{len(table)} datasets, {flagged} flagged")
    return 1 if flagged else 0


if __name__ == "__main__":
    sys.exit(main())
