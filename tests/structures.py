"""The configured structure for tests that need a StructureParameters of their own (it has no defaults of its
own: config/config.yaml is where the structure's values live)."""

from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import yaml

from contactid.config import with_defaults
from contactid.parameters import StructureParameters, structure_from_config

ROOT = Path(__file__).resolve().parents[1]


@lru_cache(maxsize=1)
def _configured() -> StructureParameters:
    with open(ROOT / "config" / "config.yaml") as fh:
        cfg = with_defaults(yaml.safe_load(fh))
    return structure_from_config(cfg["structure"], 3.95e6, 2.37e7)  # k_t, k_n: Table 3


def configured_structure(**changes) -> StructureParameters:
    """config/config.yaml's structure with Table 3's contact stiffnesses (k_t 3.95e6, k_n 2.37e7 N/m), and
    ``changes`` (StructureParameters fields)."""
    return replace(_configured(), **changes)
