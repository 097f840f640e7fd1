"""Identification of the frictional and normal contact forces at a micro-vibro-impacting joint.

The method is that of Pourahmadian, Ahmadian & Jalali, J. Sound Vib. 2012. The package holds the physics and
numerics; it knows nothing of Snakemake.
"""

import hashlib
import os
import re
import sys
import tempfile
from pathlib import Path

__version__ = "0.1.0"


def code_digest() -> str:
    """Return the sha256 digest of the package's Python sources (their names and bytes), 16 hex digits.

    It names numba's cache here and is every rule's parameter (``contactid.io.package_digest``); it runs before
    numba is imported and takes milliseconds.

    Returns
    -------
    digest : str
        The first 16 hex digits of the sha256 over every ``*.py`` file's relative path and bytes, in sorted order.
    """
    h = hashlib.sha256()
    root = Path(__file__).resolve().parent
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def numba_cache_dir(current: str, digest: str) -> Path:
    """Return where numba caches the compiled kernels for code of this digest.

    The kernels are ``@njit(cache=True)``. The directory is named by the digest, so that a changed kernel, or a
    kernel whose callee in another module changed (numba's own check reads only the kernel's file), is compiled
    afresh and never served stale.

    A directory already named by this digest (the Snakefile sets ``.snakemake/numba-cache/<digest>``) is kept; one
    named by another digest (the code changed since it was set) is swapped for this digest's; any other gets
    ``/<digest>`` appended; unset, it is ``$XDG_CACHE_HOME/contactid/numba-cache/<digest>`` (~/.cache by default).

    Parameters
    ----------
    current
        The value of NUMBA_CACHE_DIR, empty if unset.
    digest
        The code's digest (``code_digest``), 16 hex digits.

    Returns
    -------
    directory : Path
        The cache directory for code of this ``digest`` (not created here).
    """
    if current:
        path = Path(current)
        if path.name == digest:
            return path
        base = path.parent if re.fullmatch(r"[0-9a-f]{16}", path.name) else path
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "contactid" / "numba-cache"
    return base / digest


def _use_numba_cache_keyed_by_code() -> str:
    """Set NUMBA_CACHE_DIR to ``numba_cache_dir`` and return the directory.

    It runs before any kernel module imports numba. A directory that cannot be made is replaced by one under the
    temporary directory, since numba would otherwise fall back to __pycache__ beside the sources, where callees go
    stale.
    """
    current = os.environ.get("NUMBA_CACHE_DIR", "")
    target = numba_cache_dir(current, code_digest())
    if str(target) == current:
        return current
    try:
        target.mkdir(parents=True, exist_ok=True)
    except OSError:
        target = (
            Path(tempfile.gettempdir()) / f"contactid-numba-cache-{getattr(os, 'getuid', lambda: 0)()}" / target.name
        )
    os.environ["NUMBA_CACHE_DIR"] = str(target)
    if "numba" in sys.modules:  # numba read its settings when it was imported: read them again
        sys.modules["numba"].core.config.reload_config()
    return str(target)


NUMBA_CACHE_DIR = _use_numba_cache_keyed_by_code()


def use_numba_cache_under(base: Path | str) -> str:
    """Cache the kernels under ``base``/<code digest> from now on.

    The Snakefile points it at .snakemake/numba-cache; the jobs inherit the variable (NUMBA_CACHE_DIR).

    Parameters
    ----------
    base
        The directory under which the digest's directory is made.

    Returns
    -------
    directory : str
        The cache directory now in NUMBA_CACHE_DIR (``numba_cache_dir``'s, or one under the temporary directory
        where that cannot be made).
    """
    global NUMBA_CACHE_DIR
    os.environ["NUMBA_CACHE_DIR"] = str(Path(base).resolve() / code_digest())
    NUMBA_CACHE_DIR = _use_numba_cache_keyed_by_code()
    return NUMBA_CACHE_DIR
