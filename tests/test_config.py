import copy
from pathlib import Path

import pytest
from contactid.config import check_config
from contactid.schema import ConfigError
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

SCHEMA = str(Path(__file__).resolve().parents[1] / "workflow" / "schemas" / "config.schema.yaml")


def test_default_config_is_valid(default_config):
    cfg = copy.deepcopy(default_config)
    validate(cfg, SCHEMA)
    check_config(cfg)


def test_typo_is_refused_naming_the_key(default_config):
    cfg = copy.deepcopy(default_config)
    cfg["structure"]["beam"]["lenght_m"] = 0.6
    with pytest.raises(WorkflowError, match="lenght_m"):
        validate(cfg, SCHEMA)


def test_negative_length_is_refused(default_config):
    cfg = copy.deepcopy(default_config)
    cfg["structure"]["beam"]["length_m"] = -0.6
    with pytest.raises(WorkflowError, match="length_m"):
        validate(cfg, SCHEMA)


def test_sensor_outside_beam_is_refused(default_config):
    cfg = copy.deepcopy(default_config)
    cfg["structure"]["sensors"]["positions_m"] = [0.55, 0.30, 0.65]
    with pytest.raises(ConfigError, match=r"positions_m\[2\] = 0.65 m lies outside the beam; allowed range \(0, 0.6\]"):
        check_config(cfg)


def test_fewer_sensors_than_modes_is_refused(default_config):
    cfg = copy.deepcopy(default_config)
    cfg["structure"]["sensors"] = {"names": ["a1", "a2"], "positions_m": [0.55, 0.3], "masses_kg": [0.0058, 0.0058]}
    with pytest.raises(ConfigError, match="linear_modes.n_modes = 3 exceeds the number of sensors"):
        check_config(cfg)


def test_measured_source_needs_a_file(default_config):
    cfg = copy.deepcopy(default_config)
    cfg["random_test"]["source"] = "measured"
    with pytest.raises(ConfigError, match="random_test.file"):
        check_config(cfg)


def test_exponent_notation_without_a_point_is_read_as_a_number(default_config):
    """YAML 1.1 (PyYAML, Snakemake) reads 4e-05 as text: where the schema wants a number it becomes one, and the
    config validates; text of that form where text is wanted (a sensor's name) stays text."""
    import yaml
    from contactid.schema import numbers_written_as_text

    cfg = copy.deepcopy(default_config)
    cfg["rig"]["effects"] = yaml.safe_load("channel_time_skew: 4e-05")
    cfg["structure"]["sensors"]["names"] = ["1e3", "a2", "a3"]
    cfg["gap"]["n_bootstrap"] = "2e2"  # an integer
    assert cfg["rig"]["effects"]["channel_time_skew"] == "4e-05"
    changed = numbers_written_as_text(cfg, SCHEMA)
    assert sorted(changed) == [("gap.n_bootstrap", 200), ("rig.effects.channel_time_skew", 4e-05)]
    assert isinstance(cfg["gap"]["n_bootstrap"], int) and cfg["structure"]["sensors"]["names"][0] == "1e3"
    cfg["structure"]["sensors"]["names"] = default_config["structure"]["sensors"][
        "names"
    ]  # (names start with a letter)
    validate(cfg, SCHEMA)
    assert numbers_written_as_text(cfg, SCHEMA) == []


def test_a_config_without_its_optional_blocks_runs_at_the_schemas_defaults(default_config, monkeypatch):
    """The schema is the one home of the defaults: a config of the required keys alone gets every optional block
    at its documented defaults, the same from the Snakefile's validation and from ``with_defaults`` (code run
    outside Snakemake), and the linear chain uses them (frf.segment_length 65536, not an older fallback)."""
    from contactid.gap import pipeline
    from contactid.schema import with_defaults

    minimal = {"seed": default_config["seed"], "structure": copy.deepcopy(default_config["structure"])}
    filled = with_defaults(minimal)
    assert "frf" not in minimal  # a copy
    validated = copy.deepcopy(minimal)
    validate(validated, SCHEMA)
    assert filled == validated
    assert filled["frf"] == {"segment_length": 65536, "overlap": 0.5, "window": "hann"}
    assert filled["random_test"]["duration_s"] == 128.0 and filled["nonlinear"]["n_harmonics"] == 25
    assert filled["gap"]["min_gap"] == 0.006 and filled["modal"]["uncertainty_blocks"] == 4
    assert with_defaults(filled) == filled  # a complete config comes back equal
    check_config(minimal)  # the cross-field checks hold at the defaults

    seen = {}

    def frf_dataset(raw, segment_length, overlap, window, blocks):
        seen.update(segment_length=segment_length, overlap=overlap, window=window, blocks=blocks)
        raise StopIteration

    monkeypatch.setattr(pipeline, "frf_dataset", frf_dataset)
    with pytest.raises(StopIteration):
        pipeline.linear_chain(minimal, None)
    assert seen == {"segment_length": 65536, "overlap": 0.5, "window": "hann", "blocks": 4}


def test_the_settings_records_left_empty_equal_the_schemas_defaults(default_config):
    """The settings records still fall back to their own field defaults where a key is missing: those must be the
    schema's (the gap diagnosis, the friction fit, the rig's random test)."""
    from contactid.friction_fit import settings_from_config as fit_settings
    from contactid.gap.settings import GapSettings
    from contactid.rig.random_test import settings_from_config as random_test_settings
    from contactid.schema import with_defaults

    filled = with_defaults({"seed": default_config["seed"], "structure": default_config["structure"]})
    assert GapSettings.from_config({}, 1, 25) == GapSettings.from_config(filled["gap"], 1, 25)
    assert fit_settings({}) == fit_settings(filled["friction"])
    assert random_test_settings({}, {}) == random_test_settings(filled["random_test"], filled["rig"])


@pytest.mark.parametrize(
    "change, message",
    [
        (
            {"nonlinear": {"calibration_case": "lc9"}},
            r"nonlinear\.calibration_case = 'lc9' is not a load case; name one",
        ),
        ({"load_cases": {"lc1": {"A1_m_per_s2": 14.0, "A2_m_per_s2": 34.0}}}, r"nonlinear\.figure_case = 'lc3' is not"),
        ({"gap": {"candidates": ["normal_contact_damping", "teleportation"]}}, r"'teleportation' not in the candidate"),
    ],
)
def test_a_case_or_candidate_the_config_does_not_have_is_named_before_anything_runs(default_config, change, message):
    """Before, a calibration or figure case missing from load_cases stopped the DAG with a bare KeyError in an input
    function, and an unknown gap candidate passed until the diagnosis ran."""
    c = copy.deepcopy(default_config)
    for block, values in change.items():
        c[block] = {**c[block], **values} if block != "load_cases" else values
    with pytest.raises(ConfigError, match=message):
        check_config(c)
    c["gap"] = {**c["gap"], "plugins": ["my_effects"]}  # a plugin may register its own names: checked by the rule
    if "gap" in change:
        check_config(c)


# ------------------------------------------------------------------------------------------
# measured files and the config files themselves (contactid.measured_files, config.duplicate_key_errors)
# ------------------------------------------------------------------------------------------


def _measured(cfg, tmp_path, names=("lc1", "lc2")):
    for c in names:
        (tmp_path / f"{c}.nc").write_bytes(c.encode())
    cfg["load_cases"] = {c: {"source": "measured", "file": str(tmp_path / f"{c}.nc")} for c in names}
    cfg["nonlinear"].update(calibration_case=names[0], figure_case=names[0])
    return cfg


def test_a_measured_file_that_does_not_exist_is_refused_naming_key_and_near_names(default_config, tmp_path):
    cfg = _measured(copy.deepcopy(default_config), tmp_path)
    check_config(cfg)
    cfg["load_cases"]["lc2"]["file"] = str(tmp_path / "lc_2.nc")
    with pytest.raises(ConfigError, match=r"load_cases\.lc2\.file = .*lc_2\.nc': does not exist") as err:
        check_config(cfg)
    assert "did you mean" in str(err.value) and "lc2.nc" in str(err.value)
    # relative paths from the project directory (root); no root: not looked at (a config checked elsewhere)
    cfg["load_cases"]["lc2"]["file"] = "lc2.nc"
    check_config(cfg, root=tmp_path)
    with pytest.raises(ConfigError, match=r"load_cases\.lc2\.file = 'lc2\.nc': does not exist"):
        check_config(cfg, root=tmp_path / "elsewhere")
    check_config(cfg, root=None)
    # a CSV's sidecar too
    cfg["load_cases"]["lc2"] = {"source": "measured", "format": "csv", "file": str(tmp_path / "lc2.nc")}
    with pytest.raises(ConfigError, match=r"load_cases\.lc2\.sidecar = .*lc2\.yaml': does not exist"):
        check_config(cfg)


def test_two_records_on_one_file_are_refused_unless_asked_for(default_config, tmp_path):
    cfg = _measured(copy.deepcopy(default_config), tmp_path)
    cfg["load_cases"]["lc2"]["file"] = str(tmp_path / "." / "lc1.nc")  # the same file, written otherwise
    with pytest.raises(ConfigError, match=r"load_cases\.lc2\.file = .* is the file load_cases\.lc1\.file reads"):
        check_config(cfg)
    cfg["load_cases"]["lc2"]["allow_shared_file"] = True
    check_config(cfg)
    cfg["random_test"] = {"source": "measured", "file": str(tmp_path / "lc1.nc")}
    with pytest.raises(ConfigError, match="load_cases.lc1.file = .* is the file random_test.file reads"):
        check_config(cfg)


def test_duplicate_keys_are_named_with_their_lines(tmp_path):
    from contactid.config import duplicate_key_errors

    f = tmp_path / "c.yaml"
    f.write_text(
        "seed: 1\nload_cases:\n  lc2: {file: a.nc}\n  lc3: {file: b.nc}\n  lc2: {file: b.nc}\n"
        "x: &a {k: 1}\ny:\n  <<: *a\n  k: 2\n"
    )
    assert duplicate_key_errors(f) == [
        f"{f}:5: key 'lc2' repeats line 3 (YAML keeps the last silently); remove or rename one"
    ]
    f.write_text("seed: 1\nseed: 2\n")
    assert len(duplicate_key_errors(f)) == 1
    assert duplicate_key_errors(Path(__file__).resolve().parents[1] / "config" / "config.yaml") == []


def test_an_overlay_merges_as_snakemake_merges_it():
    from contactid.schema import merged_over

    base = {"a": {"b": 1, "c": [1, 2]}, "d": 1}
    assert merged_over(base, {"a": {"c": [3]}, "e": {"f": 1}}) == {"a": {"b": 1, "c": [3]}, "d": 1, "e": {"f": 1}}
    assert base == {"a": {"b": 1, "c": [1, 2]}, "d": 1}  # untouched


def test_a_file_digest_follows_its_content_not_its_modification_time(tmp_path):
    import os
    import time

    from contactid.measured_files import file_sha256, measured_digests

    rec, cache = tmp_path / "lc1.nc", tmp_path / "cache" / "digests.json"
    rec.write_bytes(b"first record")
    d1 = file_sha256(rec, cache)
    assert d1 == file_sha256(rec) and cache.exists()
    st = os.stat(rec)
    time.sleep(0.01)
    rec.write_bytes(b"other record")  # same size, then its modification time set back, as `cp -p` does
    os.utime(rec, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert os.stat(rec).st_mtime_ns == st.st_mtime_ns and os.stat(rec).st_size == st.st_size
    assert file_sha256(rec, cache) == file_sha256(rec) != d1
    # only measured files get a digest: the workflow's own records are tracked by their rules
    assert measured_digests([str(rec), "data/raw/lc2.nc"], {str(rec)}, cache) == {str(rec): file_sha256(rec)}


def test_check_config_reads_an_overlay_as_the_snakefile_does(tmp_path):
    """`contactid check-config overlay.yaml` merges it over config/config.yaml (as `snakemake --configfile` does);
    --alone checks the file by itself; a duplicate key or a missing measured file fails, naming it."""
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[1]

    def run(*args):
        return subprocess.run(
            [sys.executable, "-m", "contactid", "check-config", *args], cwd=root, capture_output=True, text=True
        )

    overlay = tmp_path / "overlay.yaml"
    overlay.write_text("frf: {segment_length: 4096}\n")
    out = run(str(overlay))
    assert out.returncode == 0 and f"{overlay} (over config/config.yaml): valid" in out.stdout
    out = run(str(overlay), "--alone")
    assert out.returncode == 1 and "'structure' is a required property" in out.stdout
    overlay.write_text(
        f"random_test: {{source: measured, file: {tmp_path / 'random_test.nc'}}}\nfrf: {{segment_length: 4096}}\n"
    )
    out = run(str(overlay))
    assert out.returncode == 1 and "random_test.file = " in out.stdout and "does not exist" in out.stdout
    overlay.write_text("frf: {segment_length: 4096}\nfrf: {segment_length: 8192}\n")
    out = run(str(overlay))
    assert out.returncode == 1 and f"{overlay}:2: key 'frf' repeats line 1" in out.stdout
