import copy
from pathlib import Path

import pytest
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from contactid.config import ConfigError, check_config

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
