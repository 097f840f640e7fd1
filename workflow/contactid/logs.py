"""Logging set-up for rule scripts: everything to the rule's log file, the package's progress to stderr as well.

The package's progress (INFO and above) goes to stderr as well as to the log file, and Snakemake shows it on the
console.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np


def fmt(value: object, digits: int = 4) -> str:
    """Return a value written for people, for a log line.

    Numbers to ``digits`` significant digits, arrays and lists as comma-separated numbers, mappings as ``key = value``
    pairs (no numpy reprs).

    Parameters
    ----------
    value
        What to write: a string, a bool, a number, a mapping, a list, a tuple or an array (numpy scalars included);
        anything else by ``str``.
    digits
        Significant digits of a floating-point number (and of those in mappings, lists and arrays).

    Returns
    -------
    text : str
        The value as text.
    """
    if isinstance(value, (str, bytes, np.str_)):
        return str(value)
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.{digits}g}"
    if isinstance(value, Mapping):
        return ", ".join(
            f"{fmt(k)} = " + (f"({fmt(v, digits)})" if isinstance(v, Mapping) else fmt(v, digits))
            for k, v in value.items()
        )
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(fmt(v, digits) for v in np.asarray(value, dtype=object).ravel()) + "]"
    return str(value)


class _ConsoleFormatter(logging.Formatter):
    """Console format ``HH:MM:SS job: message``, with the level named from WARNING up.

    No traceback (the file has it, and Python prints the uncaught one on stderr itself).

    Parameters
    ----------
    label
        The job's name shown before each message (the log file's name without its suffix).
    """

    def __init__(self, label: str):
        super().__init__("%(asctime)s %(message)s", datefmt="%H:%M:%S")
        self.label = label

    def format(self, record: logging.LogRecord) -> str:
        record = logging.makeLogRecord({**record.__dict__, "exc_info": None, "exc_text": None, "stack_info": None})
        level = f"{record.levelname}: " if record.levelno >= logging.WARNING else ""
        record.msg, record.args = f"{self.label}: {level}{record.getMessage()}", None
        return super().format(record)


class _ProgressFilter(logging.Filter):
    """Pass the package's and the scripts' records (logger ``contactid...``), and warnings from anywhere."""

    def filter(self, record: logging.LogRecord) -> bool:
        return record.name.split(".")[0] == "contactid" or record.levelno >= logging.WARNING


def setup_logging(path: str | None) -> logging.Logger:
    """Send the package's and the script's log records to a file, and its progress to stderr.

    The records go to ``path`` (or to stderr alone); the package's INFO records and every warning go to stderr as well,
    with a short format (``HH:MM:SS <log file's name>: message``). An uncaught error is logged there as well before it
    ends the script.

    Parameters
    ----------
    path
        The rule's log file, or None to log to stderr alone.

    Returns
    -------
    log : logging.Logger
        The package's logger (``contactid``).
    """
    handler = logging.FileHandler(path, mode="w") if path else logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger()
    root.handlers[:] = [handler]
    if path:
        console = logging.StreamHandler(sys.stderr)
        console.setLevel(logging.INFO)
        console.addFilter(_ProgressFilter())
        console.setFormatter(_ConsoleFormatter(Path(path).stem))
        root.handlers.append(console)
    root.setLevel(logging.INFO)
    logging.captureWarnings(True)
    log = logging.getLogger("contactid")
    previous = sys.excepthook

    def log_then_raise(kind, value, tb):
        # the rule's log names the failure too (a data error by its message, anything else with its traceback)
        from .io import RawDataError
        from .schema import ConfigError

        if issubclass(kind, (RawDataError, ConfigError)):
            log.error("%s", value)
        else:
            log.error("%s: %s", kind.__name__, value, exc_info=(kind, value, tb))
        for h in root.handlers:
            h.flush()
        previous(kind, value, tb)

    sys.excepthook = log_then_raise
    return log
