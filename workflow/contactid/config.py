"""Check the configuration for what a JSON schema cannot express.

Each failure names the key, the value, the allowed range and the fix; the Snakefile calls :func:`check_config` before
any rule runs.
"""

from __future__ import annotations

import os
from typing import Mapping

from .measured_files import record_blocks
from .schema import ConfigError, with_defaults


def duplicate_key_errors(path: str | os.PathLike) -> list[str]:
    """Return every key that a YAML mapping of the file at ``path`` gives twice.

    YAML readers keep the last silently: a second ``lc2:`` would replace the first load case. Each error reads
    "file:line: key 'k' repeats line m (YAML keeps the last silently); remove or rename one".

    Parameters
    ----------
    path
        The YAML file to read (a config file).

    Returns
    -------
    errors : list[str]
        One message per repeated key; empty when no key repeats.
    """
    import yaml

    errors = []

    class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
        pass

    def construct_mapping(loader, node, deep=False):
        seen = {}
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue
            key = loader.construct_object(key_node, deep=True)
            try:
                first = seen.get(key)
            except TypeError:  # an unhashable key: the reader's own error follows
                continue
            if first is not None:
                errors.append(
                    f"{path}:{key_node.start_mark.line + 1}: key {key!r} repeats line {first} (YAML keeps the last "
                    "silently); remove or rename one"
                )
            else:
                seen[key] = key_node.start_mark.line + 1
        return loader.construct_mapping_plain(node, deep=deep)

    _Loader.construct_mapping_plain = _Loader.construct_mapping
    _Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, construct_mapping)
    with open(path) as fh:
        yaml.load(fh, Loader=_Loader)
    return errors


def _true_structure_errors(structure: Mapping, changes: Mapping, path: str = "rig.true_structure") -> list:
    """Return the errors of rig.true_structure against the ``structure`` keys.

    rig.true_structure may hold any subset of the ``structure`` keys, each of the same kind (a number, a list of as many
    numbers, or a block); anything else is named with its fix.
    """
    errors = []
    for key, value in changes.items():
        where = f"{path}.{key}"
        if key not in structure:
            errors.append(
                f"{where} is not a key of structure (one of: {', '.join(sorted(structure))}); "
                "rig.true_structure takes any subset of the structure keys"
            )
            continue
        nominal = structure[key]
        if isinstance(nominal, Mapping):
            if not isinstance(value, Mapping):
                errors.append(f"{where} must be a block like structure.{key} (keys {', '.join(sorted(nominal))})")
            else:
                errors += _true_structure_errors(nominal, value, where)
        elif isinstance(nominal, list):
            if not isinstance(value, list) or len(value) != len(nominal):
                errors.append(f"{where} must be a list of {len(nominal)} entries like structure.{key}")
            elif key == "names" and value != nominal:
                errors.append(f"{where}: the rig's sensors are the configured ones; change positions or masses instead")
        elif value is None:
            if key != "clamp_rotational_stiffness_nm_per_rad":
                errors.append(f"{where} is null; give a number like structure.{key}")
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            hint = ""
            if isinstance(value, str):
                try:
                    float(value)
                    hint = " (YAML reads 2e11 as text: write 2.0e+11)"
                except ValueError:
                    pass
            errors.append(f"{where} = {value!r} must be a number like structure.{key}{hint}")
        elif not value > 0 and key != "gravity_m_per_s2":
            errors.append(f"{where} = {value!r} must be positive")
    return errors


def _sensor_errors(st: Mapping) -> list:
    """Return the errors of the sensors' lists and positions.

    The sensors' lists are of one length, and the sensors and the excitation lie on the beam (0, L] (m).
    """
    errors = []
    L = st["beam"]["length_m"]
    sens = st["sensors"]
    n_sens = len(sens["positions_m"])
    for key in ("names", "masses_kg"):
        if len(sens[key]) != n_sens:
            errors.append(
                f"structure.sensors.{key} has {len(sens[key])} entries but positions_m has {n_sens}; "
                "give one per sensor"
            )
    for i, x in enumerate(sens["positions_m"]):
        if not 0 < x <= L:
            errors.append(
                f"structure.sensors.positions_m[{i}] = {x} m lies outside the beam; allowed range (0, {L}] m "
                "(structure.beam.length_m)"
            )
    if not 0 < st["excitation_position_m"] <= L:
        errors.append(
            f"structure.excitation_position_m = {st['excitation_position_m']} m lies outside the beam; "
            f"allowed range (0, {L}] m"
        )
    return errors


def _mode_count_errors(cfg: Mapping) -> list:
    """Return an error for each of modal and linear_modes with more modes than sensors (Eq. 15)."""
    errors = []
    n_sens = len(cfg["structure"]["sensors"]["positions_m"])
    for block in ("modal", "linear_modes"):
        n_modes = cfg[block]["n_modes"]
        if n_modes > n_sens:
            errors.append(
                f"{block}.n_modes = {n_modes} exceeds the number of sensors ({n_sens}); "
                f"Eq. 15 needs at least as many sensors as modes: lower {block}.n_modes or add sensors"
            )
    return errors


def _random_test_errors(cfg: Mapping) -> list:
    """Return the errors of the random test's settings.

    The random test needs: a measured record's file, its band (Hz) below the anti-alias limit, the modal band inside it,
    and a rig record long enough for the FRF segments of every uncertainty block.
    """
    errors = []
    rt = cfg["random_test"]
    if rt["source"] == "measured" and not rt.get("file"):
        errors.append(
            "random_test.source is 'measured' but random_test.file is not set; give the path of the raw record"
        )
    fs = rt["sampling_rate_hz"]
    lo, hi = rt["band_hz"]
    if not lo < hi:
        errors.append(f"random_test.band_hz = [{lo}, {hi}]: the lower edge must be below the upper")
    if hi >= 0.4 * fs:
        errors.append(
            f"random_test.band_hz upper edge {hi} Hz must stay below 0.4 x sampling_rate_hz = {0.4 * fs} Hz "
            "(anti-alias filter transition)"
        )
    mlo, mhi = cfg["modal"]["band_hz"]
    if not mlo < mhi:
        errors.append(f"modal.band_hz = [{mlo}, {mhi}]: the lower edge must be below the upper")
    if rt["source"] == "rig" and (mlo < lo or mhi > hi):
        errors.append(f"modal.band_hz = [{mlo}, {mhi}] must lie inside random_test.band_hz = [{lo}, {hi}]")
    seg = cfg["frf"]["segment_length"]
    blocks = cfg["modal"]["uncertainty_blocks"]
    n = rt["duration_s"] * fs
    if rt["source"] == "rig" and n / blocks < 2 * seg:
        errors.append(
            f"random_test.duration_s = {rt['duration_s']} s gives {int(n)} samples, fewer than "
            f"2 x frf.segment_length x modal.uncertainty_blocks = {2 * seg * blocks}; lengthen the record "
            "or shorten the segment"
        )
    return errors


def _stiction_bound_errors(cfg: Mapping) -> list:
    """Return the errors of the stiction fit's stiffness search bounds (N/m), where given: low < high."""
    errors = []
    for name in ("k_t_bounds_n_per_m", "k_n_bounds_n_per_m"):
        b = cfg["stiction"].get(name)
        if b is not None and not b[0] < b[1]:
            errors.append(f"stiction.{name} = {b}: the lower bound must be below the upper")
    return errors


def _load_case_errors(cfg: Mapping) -> list:
    """Return the errors of the load cases' sources.

    A measured load case names its file; a rig load case its target amplitudes A1, A2 (m/s^2, Table 2).
    """
    errors = []
    for case, lc in (cfg.get("load_cases") or {}).items():
        if lc.get("source", "rig") == "measured":
            if not lc.get("file"):
                errors.append(f"load_cases.{case}.source is 'measured' but load_cases.{case}.file is not set")
        else:
            for key in ("A1_m_per_s2", "A2_m_per_s2"):
                if key not in lc:
                    errors.append(
                        f"load_cases.{case}.{key} is missing: a rig load case needs its target "
                        "driving-point harmonic amplitudes (Table 2)"
                    )
    return errors


def _case_reference_errors(cfg: Mapping) -> list:
    """Return the errors of the names that refer to load cases and candidates.

    nonlinear.calibration_case and nonlinear.figure_case name load cases; gap.candidates name the library's candidates
    (the built-in ones; where gap.plugins add their own, their names are checked when the rule imports them).
    """
    errors = []
    cases = sorted(cfg.get("load_cases") or {})
    for key in ("calibration_case", "figure_case"):
        name = (cfg.get("nonlinear") or {}).get(key)
        if name is not None and cases and name not in cases:
            errors.append(f"nonlinear.{key} = {name!r} is not a load case; name one of {', '.join(cases)} (load_cases)")
    gap = cfg.get("gap") or {}
    if gap.get("candidates") is not None and not gap.get("plugins"):
        from .gap.candidates import BUILTIN

        unknown = [c for c in gap["candidates"] if c not in BUILTIN]
        if unknown:
            errors.append(
                f"gap.candidates: {', '.join(map(repr, unknown))} not in the candidate library; name some of "
                f"{', '.join(BUILTIN)}, or add your own module under gap.plugins"
            )
    return errors


def _record_format_errors(cfg: Mapping) -> list:
    """Return the errors of the measured records' formats.

    A measured record in another format than netCDF has a complete channel map (``importers.record_spec``, for measured
    FRFs ``importers.frf_channels.frf_sensor_map``); a format other than netCDF is for measured records only, and FRFs
    (uff58_frf) are for the random test only.
    """
    errors = []
    for where, block in record_blocks(cfg):
        fmt = block.get("format", "netcdf")
        if fmt == "uff58_frf" and where != "random_test":
            errors.append(
                f"{where}.format = 'uff58_frf': FRFs replace the random test only; a load case needs its dual-sine "
                "time record (netcdf, uff58, tdms or csv)"
            )
        elif block.get("source", "rig") == "measured" and fmt != "netcdf" and block.get("file"):
            from .io import RawDataError

            try:
                _check_channel_map(block, where, fmt, cfg["structure"])
            except RawDataError as exc:
                errors.append(str(exc))
        elif fmt != "netcdf" and block.get("source", "rig") != "measured":
            errors.append(f"{where}.format = {block['format']!r} applies to measured files only; set source: measured")
    return errors


def _check_channel_map(block: Mapping, where: str, fmt: str, structure: Mapping) -> None:
    """Check the channel map (and a CSV's sidecar) of a measured record.

    The map must be complete and consistent; raises RawDataError otherwise.
    """
    if fmt == "uff58_frf":
        from .importers.frf_channels import frf_sensor_map

        frf_sensor_map(block, where, structure)
    else:
        from .importers import record_spec

        record_spec(block, where)


def _rig_errors(cfg: Mapping) -> list:
    """Return the errors of the virtual rig's settings.

    They are those of its true structure (``_true_structure_errors``) and of its effects
    (``rig.effects.effect_magnitudes``).
    """
    errors = _true_structure_errors(cfg["structure"], (cfg.get("rig") or {}).get("true_structure") or {})
    try:
        from .rig.effects import effect_magnitudes

        effect_magnitudes((cfg.get("rig") or {}).get("effects"))
    except ValueError as exc:
        errors.append(str(exc))
    return errors


def check_config(cfg: Mapping, source: str = "config/config.yaml", root: str | os.PathLike | None = ".") -> None:
    """Raise ConfigError on cross-field inconsistencies of a configuration.

    ``cfg`` is taken with its left-out keys at the schema's defaults (``with_defaults``). With ``root`` (the project
    directory relative paths are taken from; None: not looked at), measured files that do not exist or that two records
    share (``measured_files``) are errors too. Every error is collected before the one exception is raised.

    Parameters
    ----------
    cfg
        The whole configuration (config/config.yaml read as a mapping). Read: ``structure`` (sensors' names, positions
        and masses, beam.length_m, excitation_position_m), ``modal`` (n_modes, band_hz, uncertainty_blocks),
        ``linear_modes.n_modes``, ``random_test`` (source, file, sampling_rate_hz, band_hz, duration_s),
        ``frf.segment_length``, ``stiction`` (k_t_bounds_n_per_m, k_n_bounds_n_per_m), ``load_cases`` (source, file,
        A1_m_per_s2, A2_m_per_s2), the measured records' format and channel maps, ``nonlinear`` (calibration_case,
        figure_case), ``gap`` (candidates, plugins) and ``rig`` (true_structure, effects).
    source
        The name the message gives the configuration (its file).
    root
        The project directory measured files' relative paths are taken from; None: the files are not looked at.

    Raises
    ------
    ConfigError
        When any check fails; the message lists every failure, each with its key, value, allowed range and fix.
    """
    from .measured_files import missing_file_errors, shared_file_errors

    cfg = with_defaults(cfg)
    files = [*missing_file_errors(cfg, root), *shared_file_errors(cfg, root)] if root is not None else []
    errors = [
        *files,
        *_sensor_errors(cfg["structure"]),
        *_mode_count_errors(cfg),
        *_random_test_errors(cfg),
        *_stiction_bound_errors(cfg),
        *_load_case_errors(cfg),
        *_case_reference_errors(cfg),
        *_record_format_errors(cfg),
        *_rig_errors(cfg),
    ]
    if errors:
        raise ConfigError(f"{source}: invalid configuration:\n  - " + "\n  - ".join(errors))
