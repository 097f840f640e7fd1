"""Logging set-up for rule scripts: everything to the rule's log file."""

from __future__ import annotations

import logging
import sys


def setup_logging(path: str | None) -> logging.Logger:
    """Send the package's and the script's log records to ``path`` (or stderr); an uncaught error is
    logged there as well before it ends the script."""
    handler = logging.FileHandler(path, mode="w") if path else logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger()
    root.handlers[:] = [handler]
    root.setLevel(logging.INFO)
    logging.captureWarnings(True)
    log = logging.getLogger("contactid")
    previous = sys.excepthook

    def log_then_raise(kind, value, tb):
        # the rule's log names the failure too (a data error by its message, anything else with its traceback)
        from .config import ConfigError
        from .io import RawDataError

        if issubclass(kind, (RawDataError, ConfigError)):
            log.error("%s", value)
        else:
            log.error("%s: %s", kind.__name__, value, exc_info=(kind, value, tb))
        handler.flush()
        previous(kind, value, tb)

    sys.excepthook = log_then_raise
    return log
