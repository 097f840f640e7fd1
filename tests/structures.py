"""The configured structure for tests that need a StructureParameters of their own (it has no defaults of its
own: config/config.yaml is where the structure's values live), a mass candidate's structure, a dual-sine
record's harmonics for the inverse identification, and H1 as scipy's welch and csd give it; the benchmarks use them
too."""

from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import yaml
from contactid.parameters import StructureParameters, structure_from_config
from contactid.schema import with_defaults

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


def mass_candidate_structure() -> StructureParameters:
    """A structure the transducer-mass candidate builds (masses 7.5 % heavy, E 0.3 % low, its refitted k_t): the
    contact's eta static shape lies within 4e-8 of the lowest 20 modes' span there, where the frequency map's Ritz
    basis once failed (its Cholesky factor of V^T M V was singular)."""
    return configured_structure(
        youngs_modulus=215782073068.41495,
        force_transducer_mass=0.022575,
        sensor_masses=(0.006235, 0.006235, 0.006235),
        k_t=14941288.94,
    )


def dual_sine_harmonics(seed: int, K: int = 25) -> tuple[np.ndarray, np.ndarray]:
    """A dual-sine record's force harmonics (K,) (7.5 N at w, 1.9 N at 3 w) and three sensors' acceleration harmonics
    (3, K), random and decaying with the harmonic's order, w and 3 w forty times larger."""
    rng = np.random.default_rng(seed)
    F = np.zeros(K, complex)
    F[[0, 2]] = [7.5, 1.9j]
    A = (rng.normal(size=(3, K)) + 1j * rng.normal(size=(3, K))) * np.exp(-0.3 * np.arange(K))
    A[:, [0, 2]] *= 40.0
    return F, A


def welch_csd_frf(force, responses, fs, segment_length, overlap=0.5, window="hann"):
    """(frequencies (Hz), H1, coherence) as contactid.signals.h1_frf computed them before: scipy.signal.welch of the
    force, then csd and welch per response (constant detrending, the overlap rounded to whole samples)."""
    import scipy.signal

    kw = dict(fs=fs, window=window, nperseg=segment_length, noverlap=int(round(overlap * segment_length)))
    f, gff = scipy.signal.welch(force, detrend="constant", **kw)
    h1, coh = [], []
    for x in responses:
        gfx = scipy.signal.csd(force, x, detrend="constant", **kw)[1]
        gxx = scipy.signal.welch(x, detrend="constant", **kw)[1]
        h1.append(gfx / gff)
        coh.append(np.abs(gfx) ** 2 / (gff * gxx))
    return f, np.array(h1), np.array(coh)
