"""Seeded random streams: one top-level seed, one independent stream per named purpose."""

from __future__ import annotations

import zlib

import numpy as np


def generator(seed: int, purpose: str) -> np.random.Generator:
    """Return a random generator for one purpose, derived from the config's seed.

    The same (seed, purpose) gives the same stream on every run; different purposes give independent streams, so
    adding a consumer never shifts another.

    Parameters
    ----------
    seed
        The config's top-level seed.
    purpose
        The stream's name, for example "random_test/noise" (its CRC-32 is the seed sequence's spawn key).

    Returns
    -------
    rng : np.random.Generator
        The purpose's stream.
    """
    key = zlib.crc32(purpose.encode("utf-8"))
    return np.random.default_rng(np.random.SeedSequence(entropy=int(seed), spawn_key=(key,)))
