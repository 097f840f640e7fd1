"""The configuration's schema, the one home of every setting and its default.

``workflow/schemas/config.schema.yaml`` (JSON Schema in YAML) declares every key, its type, range and default; the
Snakefile's validation fills the defaults into the workflow's config, ``with_defaults`` into a config used outside
Snakemake, and ``schema_defaults`` gives a block's defaults to code that merges keys over them. The checks a schema
cannot express are ``contactid.config``'s.
"""

from __future__ import annotations

import copy
import functools
import re
from pathlib import Path
from typing import Mapping

# the one home of every default: the schema's ``default``s (every optional block defaults to {}, so that its keys'
# defaults fill in where the block is left out); the Snakefile's validation fills them into the workflow's config,
# ``with_defaults`` into a config used outside Snakemake
SCHEMA = Path(__file__).resolve().parents[1] / "schemas" / "config.schema.yaml"


class ConfigError(ValueError):
    """An inconsistent configuration."""


# a number in exponent notation without a decimal point (4e-05): YAML 1.1, which PyYAML and Snakemake read, takes it
# for text; YAML 1.2 and every other reader for a number
_EXPONENT_NUMBER = re.compile(r"^[-+]?(\d+|\d+\.\d*|\.\d+)[eE][-+]?\d+$")


def load_schema(schema: Mapping | Path | str) -> dict:
    """Return the schema as a mapping.

    ``schema`` itself where it is one, else a copy of the file at that path (the file is read once and cached).

    Parameters
    ----------
    schema
        The schema as a mapping, or the path of its YAML file.

    Returns
    -------
    schema : dict
        The schema (a shallow copy of a mapping given; a deep copy of the cached file's).
    """
    if isinstance(schema, Mapping):
        return dict(schema)
    return copy.deepcopy(_schema_file(str(Path(schema).resolve())))


@functools.lru_cache(maxsize=4)
def _schema_file(path: str) -> dict:
    import yaml

    with open(path) as fh:
        return yaml.load(fh, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


def with_defaults(cfg: Mapping, schema: Mapping | Path | str = SCHEMA) -> dict:
    """Return a copy of a config with the schema's defaults filled in where keys are left out.

    The defaults are filled in as the Snakefile's validation fills them (a block's own keys too, where the block is
    left out), so that code run outside Snakemake (tests, benchmarks, the blind benchmark's items) uses the values
    the workflow would. A config that is already complete comes back equal. Validation errors are not raised here
    (the Snakefile's check does).

    Parameters
    ----------
    cfg
        The configuration (any subset of the schema's blocks and keys); not changed.
    schema
        The schema as a mapping or the path of its YAML file; by default the workflow's.

    Returns
    -------
    filled : dict
        A deep copy of ``cfg`` with the defaults filled in.
    """
    import jsonschema

    base = jsonschema.Draft202012Validator

    def properties(validator, props, instance, sch):
        if isinstance(instance, dict):
            for key, sub in props.items():
                if isinstance(sub, Mapping) and "default" in sub:
                    instance.setdefault(key, copy.deepcopy(sub["default"]))
        yield from base.VALIDATORS["properties"](validator, props, instance, sch)

    filled = copy.deepcopy(dict(cfg))
    for _ in jsonschema.validators.extend(base, {"properties": properties})(load_schema(schema)).iter_errors(filled):
        pass
    return filled


@functools.lru_cache(maxsize=None)
def filled_defaults() -> dict:
    """Return the schema's defaults of every key: the config a user who gives nothing gets.

    Returns
    -------
    defaults : dict
        The defaults; cached and shared by every caller: do not change it.
    """
    return with_defaults({})


def schema_defaults(*path: str) -> dict:
    """Return the schema's defaults of the block at a path, for code that merges a block's keys over them.

    A copy, read from the schema, the one home of the defaults.

    Parameters
    ----------
    *path
        The block's keys from the config's top, for example "rig" or "rig", "true_damping".

    Returns
    -------
    defaults : dict
        A deep copy of the block's defaults.
    """
    node = filled_defaults()
    for key in path:
        node = node[key]
    return copy.deepcopy(node)


def numbers_written_as_text(cfg: dict, schema: Mapping | Path | str) -> list:
    """Make numbers, in place, of the values YAML 1.1 read as text where the schema wants a number.

    ``channel_time_skew: 4e-05`` is the text '4e-05' to PyYAML (it wants 4.0e-05), which the schema would refuse as
    "not of type 'number'". Only values of that form where a number is wanted are changed: a name or a path that
    looks like one elsewhere stays text.

    Parameters
    ----------
    cfg
        The configuration as read; changed in place.
    schema
        The schema as a mapping or the path of its YAML file.

    Returns
    -------
    changed : list
        [(dotted key, number)] of the values changed (an int where the schema wants an integer), each number in the
        unit of its key; empty where nothing changed.
    """

    def texts(node):
        if isinstance(node, str):
            yield node
        elif isinstance(node, Mapping):
            for v in node.values():
                yield from texts(v)
        elif isinstance(node, list):
            for v in node:
                yield from texts(v)

    if not any(_EXPONENT_NUMBER.match(t.strip()) for t in texts(cfg)):
        return []  # nothing to look at (the usual case): no schema pass
    import jsonschema

    schema = load_schema(schema)
    changed = []
    for err in jsonschema.Draft202012Validator(schema).iter_errors(cfg):
        wanted = err.validator_value if isinstance(err.validator_value, list) else [err.validator_value]
        if (
            err.validator != "type"
            or not isinstance(err.instance, str)
            or not ({"number", "integer"} & set(wanted))
            or not _EXPONENT_NUMBER.match(err.instance.strip())
        ):
            continue
        value = float(err.instance)
        if "number" not in wanted:  # an integer
            if not value.is_integer():
                continue
            value = int(value)
        *parents, last = list(err.absolute_path)
        node = cfg
        for key in parents:
            node = node[key]
        node[last] = value
        changed.append((".".join(str(k) for k in err.absolute_path), value))
    return changed


def merged_over(base: Mapping, overlay: Mapping) -> dict:
    """Return one config merged over another, as Snakemake merges a --configfile over the Snakefile's configfile.

    Blocks are merged key by key, recursively; any other value (a list, a number) is replaced whole.

    Parameters
    ----------
    base
        The config merged over; not changed.
    overlay
        The config whose values win; not changed.

    Returns
    -------
    merged : dict
        A deep copy of ``base`` with ``overlay`` merged over it.
    """
    out = copy.deepcopy(dict(base))
    for key, value in overlay.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = merged_over(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out
