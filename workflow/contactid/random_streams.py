"""Seeded random streams: one top-level seed, one independent stream per named purpose."""

from __future__ import annotations

import zlib

import numpy as np


def generator(seed: int, purpose: str) -> np.random.Generator:
    """A ``numpy.random.Generator`` for ``purpose`` derived from the config's ``seed``.

    The same (seed, purpose) gives the same stream on every run; different
    purposes give independent streams, so adding a consumer never shifts another.
    """
    key = zlib.crc32(purpose.encode("utf-8"))
    return np.random.default_rng(np.random.SeedSequence(entropy=int(seed), spawn_key=(key,)))
