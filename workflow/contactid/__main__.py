"""Command line: `python -m contactid audit [paths] [--out file.csv]`."""

import sys

from .audit import main as audit_main


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] != "audit":
        print("usage: python -m contactid audit [results data] [--out results/audit.csv]", file=sys.stderr)
        return 2
    return audit_main(argv[1:])


if __name__ == "__main__":
    sys.exit(main())
