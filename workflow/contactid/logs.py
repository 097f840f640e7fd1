"""Logging set-up for rule scripts: everything to the rule's log file."""

from __future__ import annotations

import logging
import sys


def setup_logging(path: str | None) -> logging.Logger:
    """Send the package's and the script's log records to ``path`` (or stderr)."""
    handler = logging.FileHandler(path, mode="w") if path else logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger()
    root.handlers[:] = [handler]
    root.setLevel(logging.INFO)
    logging.captureWarnings(True)
    return logging.getLogger("contactid")
