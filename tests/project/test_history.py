"""benchmarks/history.csv, the machine-readable log of the runs docs/measurements.md reports: its columns, and that
every row's date, commit and wall time are well formed."""

import csv
import re
from pathlib import Path

HISTORY = Path(__file__).resolve().parents[2] / "benchmarks" / "history.csv"
COLUMNS = ["date", "commit", "target", "seconds", "scores", "machine", "source"]
DATE = re.compile(r"^\d{4}-\d{2}-\d{2}$")
COMMIT = re.compile(r"^[0-9a-f]{7,40}$")


def _rows() -> list:
    with open(HISTORY, newline="") as fh:
        reader = csv.DictReader(fh)
        assert reader.fieldnames == COLUMNS
        return list(reader)


def test_history_has_exactly_the_columns():
    with open(HISTORY, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == COLUMNS
    assert all(len(row) == len(COLUMNS) for row in rows), "a row with another number of fields"


def test_history_rows_are_well_formed():
    rows = _rows()
    assert len(rows) >= 50
    for row in rows:
        assert DATE.match(row["date"]), row
        assert row["commit"] == "" or COMMIT.match(row["commit"]), row
        if row["seconds"]:
            assert float(row["seconds"]) > 0, row
        assert row["target"] and row["source"], row
        assert row["seconds"] or row["scores"], f"a run with neither a wall time nor scores: {row}"


def test_history_is_sorted_by_date_then_commit():
    keys = [(row["date"], row["commit"]) for row in _rows()]
    assert keys == sorted(keys)
