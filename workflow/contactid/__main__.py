"""Command line: `python -m contactid {audit, check-config, compile-kernels} ...` (also installed as the `contactid`
command).

audit            the provenance and integrity of every dataset in results/ and data/
check-config     a config file against the schema and the cross-field checks, before any rule runs
compile-kernels  numba's kernels compiled into the workflow's cache ahead of its first run (`make env` runs it)
"""

import argparse
import sys


def check_config_main(argv) -> int:
    """Validate a config file as the Snakefile does (schema with its defaults, then the cross-field checks);
    print what is wrong (key and how to fix it) or that it is valid. Returns 1 when it is not."""
    import jsonschema
    import yaml

    from .config import SCHEMA, ConfigError, _load_schema, check_config, numbers_written_as_text, with_defaults

    parser = argparse.ArgumentParser(prog="contactid check-config", description=check_config_main.__doc__)
    parser.add_argument("config", nargs="?", default="config/config.yaml", help="the config file (YAML)")
    args = parser.parse_args(argv)
    try:
        with open(args.config) as fh:
            cfg = yaml.safe_load(fh) or {}
    except (OSError, yaml.YAMLError) as exc:
        print(f"{args.config}: cannot be read: {exc}")
        return 1
    for key, value in numbers_written_as_text(cfg, SCHEMA):
        print(f"{args.config}: {key}: read as the number {value!r} (write exponents with a decimal point: 4.0e-05)")
    filled = with_defaults(cfg)
    errors = sorted(
        jsonschema.Draft202012Validator(_load_schema(SCHEMA)).iter_errors(filled), key=lambda e: list(e.path)
    )
    for e in errors:
        print(f"{args.config}: {'.'.join(str(p) for p in e.path) or '(top level)'}: {e.message}")
    if errors:
        return 1
    try:
        check_config(filled, args.config)
    except ConfigError as exc:
        print(exc)
        return 1
    print(f"{args.config}: valid ({len(filled.get('load_cases', {}))} load cases)")
    return 0


def compile_kernels_main(argv) -> int:
    """Compile numba's kernels into the cache the workflow's jobs read (.snakemake/numba-cache/<code digest> under
    the project directory), so that its first run does not compile them in its jobs. Where the config cannot be
    read, says so and leaves the compiling to the workflow (exit 0: nothing is lost)."""
    import yaml

    from . import use_numba_cache_under
    from .kernels import KERNEL_GROUPS, compile_kernels

    parser = argparse.ArgumentParser(prog="contactid compile-kernels", description=compile_kernels_main.__doc__)
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


def main(argv=None) -> int:
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
