"""One home per setting: the schema's defaults, config/config.yaml and config/README.md's key tables agree. The
schema is the source; config.yaml gives every default the schema gives, with the same value; every schema key with a
default has a row in config/README.md whose default cell says that value."""

import math
import re
from pathlib import Path

import yaml
from contactid.schema import filled_defaults

ROOT = Path(__file__).resolve().parents[2]


def _leaves(node, prefix=""):
    if isinstance(node, dict) and node:
        for k, v in node.items():
            yield from _leaves(v, f"{prefix}.{k}" if prefix else k)
    else:
        yield prefix, node


def _schema_defaults() -> dict:
    # load_cases is the user's data (a mapping of cases), not a setting with a default value
    return {k: v for k, v in _leaves(filled_defaults()) if not k.startswith("load_cases")}


def _split_top(cell: str, n: int) -> list:
    """``cell`` split at the commas outside brackets into ``n`` pieces (a row documenting n keys at once)."""
    if n == 1:
        return [cell]
    parts, depth, cur = [], 0, ""
    for ch in cell:
        depth += ch in "[{("
        depth -= ch in "]})"
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    parts.append(cur)
    return [p.strip() for p in parts] if len(parts) == n else [cell] * n


def _readme_rows() -> dict:
    """{key as written: default cell} of every `| `key` | default | ... |` row (several keys in one row split)."""
    rows = {}
    for line in (ROOT / "config" / "README.md").read_text().splitlines():
        m = re.match(r"^\| ((?:`[\w.]+`(?:, )?)+) \| ([^|]*) \|", line)
        if not m:
            continue
        keys = re.findall(r"`([\w.]+)`", m.group(1))
        for k, cell in zip(keys, _split_top(m.group(2).strip(), len(keys))):
            rows.setdefault(k, []).append(cell)
    return rows


def _number(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


def _says(cell: str, value) -> bool:
    """Whether a README default cell states ``value`` (numbers compared as numbers: 1.0e-4 is 0.0001)."""
    if isinstance(value, bool):
        return str(value).lower() in cell.lower()
    if isinstance(value, (int, float)):
        return any(
            _number(t) is not None and math.isclose(float(t), float(value), rel_tol=1e-9, abs_tol=1e-15)
            for t in re.findall(r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?", cell, flags=re.I)
        )
    if isinstance(value, str):
        return value in cell
    if isinstance(value, list):
        return all(_says(cell, v) for v in value) if value else ("[]" in cell or "none" in cell.lower())
    return True  # null and mappings: described in words


def _row_for(key: str, rows: dict):
    parts = key.split(".")
    for i in range(len(parts)):  # the longest suffix written as a row key
        cells = rows.get(".".join(parts[i:]))
        if cells:
            return cells
    for i in range(len(parts) - 1, 0, -1):  # a mapping documented as one row: {key: value, ...}
        cells = rows.get(".".join(parts[:i]).split(".")[-1])
        if cells and any(f"{parts[i]}:" in c for c in cells):
            return [c for c in cells if f"{parts[i]}:" in c]
    return None


def test_config_yaml_gives_the_schemas_defaults():
    cfg = dict(_leaves(yaml.safe_load((ROOT / "config" / "config.yaml").read_text())))
    schema = _schema_defaults()
    differ = {k: (cfg[k], v) for k, v in schema.items() if k in cfg and cfg[k] != v}
    assert not differ, f"config/config.yaml and the schema's defaults differ: {differ}"


def test_every_schema_default_has_a_readme_row_that_says_it():
    rows = _readme_rows()
    missing, wrong = [], []
    for key, value in _schema_defaults().items():
        cells = _row_for(key, rows)
        if cells is None:
            missing.append(key)
        elif not any(_says(c, value) for c in cells):
            wrong.append((key, value, cells))
    assert not missing, f"config/README.md has no row for {missing}"
    assert not wrong, f"config/README.md's default differs from the schema's: {wrong}"


def test_the_drift_check_sees_a_wrong_default():
    assert _says("0.5, hann", 0.5) and _says("1.0e-4", 0.0001) and not _says("2.37e+7", 2.4e7)
    assert _split_top("[1e5, 1e9], [1e5, 1e11]", 2) == ["[1e5, 1e9]", "[1e5, 1e11]"]
    rows = {"place": ["`{drift_z: 8.0, residual_factor: 20.0}`"]}
    assert _row_for("gap.place.drift_z", rows) == rows["place"]


def test_the_settings_objects_defaults_are_the_schemas():
    """The settings dataclasses keep field defaults (for calls outside the workflow); each equals what the schema's
    defaults give through the object's own from_config, so no setting has a second default of its own."""
    import dataclasses

    from contactid.friction_fit import FitSettings, settings_from_config
    from contactid.gap.place import PlaceThresholds
    from contactid.gap.settings import GapSettings

    pairs = [
        (GapSettings(), GapSettings.from_config({}, 0, GapSettings().identification_harmonics)),
        (FitSettings(), settings_from_config({})),
        (PlaceThresholds(), PlaceThresholds.from_config(None)),
    ]
    for plain, from_schema in pairs:
        differ = {
            f.name: (getattr(plain, f.name), getattr(from_schema, f.name))
            for f in dataclasses.fields(plain)
            if str(getattr(plain, f.name)) != str(getattr(from_schema, f.name))
        }
        assert not differ, f"{type(plain).__name__}'s field defaults differ from the schema's: {differ}"
