"""The contactid command line: the audit, the config's check and the kernels' compilation.

`python -m contactid {audit, check-config, compile-kernels} ...` (also installed as the `contactid` command):

audit            the provenance and integrity of every dataset in results/ and data/
check-config     a config file against the schema and the cross-field checks, before any rule runs
compile-kernels  numba's kernels compiled into the workflow's cache ahead of its first run (`make env` runs it)
"""

import argparse
import inspect
import os
import sys
from collections.abc import Callable, Sequence


def command_help(command: Callable[..., int]) -> str:
    """Return a command's help text: its docstring's prose, without the numpydoc sections.

    Parameters
    ----------
    command
        The function that runs the command (its docstring opens with the summary line, then the prose).

    Returns
    -------
    text : str
        The docstring up to its first section heading (``Parameters``, ``Returns``, ...).
    """
    text = inspect.cleandoc(command.__doc__ or "")
    lines = text.splitlines()
    for i in range(len(lines) - 1):
        if lines[i + 1].strip() and set(lines[i + 1].strip()) == {"-"} and len(lines[i + 1]) == len(lines[i]):
            return "\n".join(lines[:i]).rstrip()
    return text


def check_config_main(argv: Sequence[str]) -> int:
    """Validate a config file as the Snakefile reads it, and print what is wrong or that it is valid.

    The file is merged over the base config (config/config.yaml, as `snakemake --configfile FILE` merges it; the
    base itself, or a file with --alone, is checked alone), then checked for duplicate keys, against the schema with
    its defaults, by the cross-field checks and for the measured files (relative paths from the current directory,
    the project's). What is wrong is printed with its key and how to fix it.

    Parameters
    ----------
    argv
        The command's arguments after ``check-config``: the config file (default config/config.yaml), ``--base``
        (the config it is merged over) and ``--alone``.

    Returns
    -------
    status : int
        The exit status: 0 when the config is valid, 1 when it is not (or cannot be read).
    """
    import jsonschema
    import yaml

    from .config import check_config, duplicate_key_errors
    from .schema import SCHEMA, ConfigError, load_schema, merged_over, numbers_written_as_text, with_defaults

    parser = argparse.ArgumentParser(prog="contactid check-config", description=command_help(check_config_main))
    parser.add_argument("config", nargs="?", default="config/config.yaml", help="the config file (YAML)")
    parser.add_argument("--base", default="config/config.yaml", help="the config the file is merged over")
    parser.add_argument("--alone", action="store_true", help="check the file alone, not merged over the base")
    args = parser.parse_args(argv)
    alone = args.alone or os.path.realpath(args.config) == os.path.realpath(args.base)
    files = [args.config] if alone else [args.base, args.config]
    cfg = {}
    for path in files:
        try:
            with open(path) as fh:
                part = yaml.safe_load(fh) or {}
            duplicates = duplicate_key_errors(path)
        except (OSError, yaml.YAMLError) as exc:
            print(f"{path}: cannot be read: {exc}")
            return 1
        if duplicates:
            print("\n".join(duplicates))
            return 1
        if not isinstance(part, dict):
            print(f"{path}: must hold keys at its top level (a YAML mapping)")
            return 1
        cfg = merged_over(cfg, part)
    name = args.config if alone else f"{args.config} (over {args.base})"
    for key, value in numbers_written_as_text(cfg, SCHEMA):
        print(f"{name}: {key}: read as the number {value!r} (write exponents with a decimal point: 4.0e-05)")
    filled = with_defaults(cfg)
    errors = sorted(
        jsonschema.Draft202012Validator(load_schema(SCHEMA)).iter_errors(filled), key=lambda e: list(e.path)
    )
    for e in errors:
        print(f"{name}: {'.'.join(str(p) for p in e.path) or '(top level)'}: {e.message}")
    if errors:
        return 1
    try:
        check_config(filled, name)
    except ConfigError as exc:
        print(exc)
        return 1
    print(f"{name}: valid ({len(filled.get('load_cases', {}))} load cases)")
    return 0


def compile_kernels_main(argv: Sequence[str]) -> int:
    """Compile numba's kernels into the cache the workflow's jobs read.

    The cache is .snakemake/numba-cache/<code digest> under the project directory, so that the workflow's first run
    does not compile the kernels in its jobs. Where the config cannot be read, this says so and leaves the compiling
    to the workflow (exit 0: nothing is lost).

    Parameters
    ----------
    argv
        The command's arguments after ``compile-kernels``: the config file (default config/config.yaml),
        ``--group`` (only these kernels, repeatable) and ``--cache`` (the cache's base directory).

    Returns
    -------
    status : int
        The exit status: always 0 (a config that cannot be read leaves the compiling to the workflow).
    """
    import yaml

    from . import use_numba_cache_under
    from .kernels import KERNEL_GROUPS, compile_kernels

    parser = argparse.ArgumentParser(prog="contactid compile-kernels", description=command_help(compile_kernels_main))
    parser.add_argument("config", nargs="?", default="config/config.yaml", help="the config file (YAML)")
    parser.add_argument(
        "--group", choices=sorted(KERNEL_GROUPS), action="append", help="only these kernels (default: all)"
    )
    parser.add_argument("--cache", default=".snakemake/numba-cache", help="the cache's base directory")
    args = parser.parse_args(argv)
    cache = use_numba_cache_under(args.cache)
    try:
        with open(args.config) as fh:
            cfg = yaml.safe_load(fh) or {}
        compile_kernels(cfg, args.group)
    except Exception as exc:  # a broken config is the workflow's to report, with its file and key
        print(f"contactid compile-kernels: not compiled ahead ({args.config}: {exc}); the workflow's jobs will")
        return 0
    print(f"contactid compile-kernels: {', '.join(args.group or sorted(KERNEL_GROUPS))} kernels in {cache}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``contactid`` command line: dispatch to audit, check-config or compile-kernels.

    Parameters
    ----------
    argv
        The command-line arguments after the program's name, the subcommand first (None: ``sys.argv[1:]``).

    Returns
    -------
    status : int
        The subcommand's exit status; 2 (after printing the help) when no subcommand is given.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = argparse.ArgumentParser(
        prog="contactid",
        description="contactid: contact-force identification at a micro-vibro-impacting joint (the workflow's "
        "command-line tools; the workflow itself runs with `snakemake`).",
    )
    sub = parser.add_subparsers(dest="command", metavar="{audit,check-config,compile-kernels}")
    sub.add_parser(
        "audit", help="check the provenance and integrity of every dataset (results/, data/)", add_help=False
    )
    sub.add_parser("check-config", help="validate a config file before any rule runs", add_help=False)
    sub.add_parser("compile-kernels", help="compile numba's kernels ahead of the first run", add_help=False)
    if not argv:
        parser.print_help()
        return 2
    args, rest = parser.parse_known_args(argv[:1])
    if args.command == "audit":
        from .audit import main as audit_main

        return audit_main(argv[1:])
    if args.command == "compile-kernels":
        return compile_kernels_main(argv[1:])
    return check_config_main(argv[1:])


if __name__ == "__main__":
    sys.exit(main())
