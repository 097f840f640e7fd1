"""The measured files a config names: that they exist, that no two records share one, and their content digests.

A measured file is an input of the workflow in Snakemake's sense and its content, not its modification time, decides
what is computed again: the rules that read one take its sha256 as a parameter (``measured_digests``), so that a
record replaced by another with an older modification time (``cp -p``, ``rsync -a``, a restored backup) reruns
everything downstream of it. A digest is computed once per version of a file: it is kept in a small cache keyed on
the file's size, modification and status-change times (ctime, which no copy can set back) and inode.
"""

from __future__ import annotations

import difflib
import json
import os
from pathlib import Path
from typing import Iterable, Iterator, Mapping


def record_blocks(cfg: Mapping) -> list[tuple[str, Mapping]]:
    """Return the (config key, block) of every record the config names: the random test, then each load case.

    Parameters
    ----------
    cfg
        The workflow's config: its ``random_test`` block and the ``load_cases`` mapping are read.

    Returns
    -------
    blocks : list[tuple[str, Mapping]]
        ("random_test", block) then ("load_cases.<case>", block) for each load case; a missing block is {}.
    """
    blocks = [("random_test", cfg.get("random_test") or {})]
    return blocks + [(f"load_cases.{c}", lc or {}) for c, lc in (cfg.get("load_cases") or {}).items()]


def measured_records(cfg: Mapping) -> Iterator[tuple[str, Mapping]]:
    """Yield the (config key, block) of every record the config reads from a file.

    Those of ``record_blocks`` whose ``source`` is measured, with a ``file``.

    Parameters
    ----------
    cfg
        The workflow's config: its ``random_test`` block and the ``load_cases`` mapping are read (each block's
        ``source`` and ``file``).

    Yields
    ------
    record : tuple[str, Mapping]
        The record's config key ("random_test" or "load_cases.<case>") and its block.
    """
    for where, block in record_blocks(cfg):
        if block.get("source", "rig") == "measured" and block.get("file"):
            yield where, block


def record_files(block: Mapping) -> list[tuple[str, str]]:
    """Return the (key, path) of the files a measured record's block reads: its ``file``, and for CSV its sidecar YAML.

    Parameters
    ----------
    block
        A measured record's config block: ``file``, ``format`` and (for CSV) ``sidecar`` are read.

    Returns
    -------
    files : list[tuple[str, str]]
        ("file", path) and, for CSV, ("sidecar", the sidecar YAML's path).
    """
    files = [("file", str(block["file"]))]
    if block.get("format") == "csv":
        from .importers import sidecar_path

        files.append(("sidecar", sidecar_path(block["file"], block.get("sidecar"))))
    return files


def _near_names(path: Path) -> str:
    """Return ' (did you mean ...?)' for the closest names in the file's folder, or what the folder holds, or ''."""
    folder = path.parent
    if not folder.is_dir():
        return f" (the folder {str(folder)!r} does not exist either)"
    names = sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))
    close = difflib.get_close_matches(path.name, names, n=3, cutoff=0.6)
    if close:
        return f" (did you mean {', '.join(repr(str(folder / n)) for n in close)}?)"
    return f" ({str(folder)!r} holds {', '.join(names[:8])}{', ...' if len(names) > 8 else ''})" if names else ""


def missing_file_errors(cfg: Mapping, root: str | os.PathLike = ".") -> list[str]:
    """Return a message for every measured file (and CSV sidecar) the config names that does not exist.

    Each message names the key, the path, where it was looked for, the closest names in its folder, and the fix.

    Parameters
    ----------
    cfg
        The workflow's config: the ``random_test`` block and each of ``load_cases`` (``source``, ``file``,
        ``format``, ``sidecar``) are read.
    root
        The directory relative paths are taken from (the project directory, where Snakemake runs).

    Returns
    -------
    errors : list[str]
        One message per missing file; empty when every file exists.
    """
    errors = []
    root = Path(root)
    for where, block in measured_records(cfg):
        for key, path in record_files(block):
            full = Path(path) if os.path.isabs(path) else root / path
            if not full.is_file():
                what = "is a folder, not a file" if full.is_dir() else "does not exist"
                errors.append(
                    f"{where}.{key} = {path!r}: {what} (looked for {str(full.resolve())!r}){_near_names(full)}; "
                    f"correct {where}.{key} (relative paths are taken from the project directory)"
                )
    return errors


def shared_file_errors(cfg: Mapping, root: str | os.PathLike = ".") -> list[str]:
    """Return a message for every record that reads a file an earlier record reads already.

    Two records read from one file: a copy-paste slip that would identify one record twice. Refused unless the later
    load case says ``allow_shared_file: true``; the random test and a load case never share a file.

    Parameters
    ----------
    cfg
        The workflow's config: the ``random_test`` block and each of ``load_cases`` (``source``, ``file``,
        ``allow_shared_file``) are read.
    root
        The directory relative paths are taken from (the project directory, where Snakemake runs).

    Returns
    -------
    errors : list[str]
        One message per shared file, with the fix; empty when no two records share one.
    """
    errors, seen = [], {}
    root = Path(root)
    for where, block in measured_records(cfg):
        path = str(block["file"])
        key = os.path.realpath(path if os.path.isabs(path) else root / path)
        if key not in seen:
            seen[key] = where
            continue
        first = seen[key]
        if first == "random_test" or not block.get("allow_shared_file", False):
            fix = (
                "the random test and a dual-sine load case are different tests"
                if first == "random_test"
                else f"give each its own record, or set {where}.allow_shared_file: true if the same record is meant"
            )
            errors.append(f"{where}.file = {path!r} is the file {first}.file reads already; {fix}")
    return errors


# -------------------------------------------------------------------------------------------------------------------
# content digests
# -------------------------------------------------------------------------------------------------------------------


def _stamp(st: os.stat_result) -> list:
    return [st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino]


def file_sha256(path: str | os.PathLike, cache: str | os.PathLike | None = None) -> str:
    """Return the sha256 of a file's content.

    With ``cache`` (a JSON file), a digest is reused while the file's size, modification time, status-change time
    and inode are those it was computed at; any write to the file changes its status-change time, so a replaced file
    is read again whatever its modification time says.

    Parameters
    ----------
    path
        The file (symbolic links are resolved).
    cache
        The JSON file of digests to reuse and update (None: no cache; a cache that cannot be read or written is left
        as it is).

    Returns
    -------
    digest : str
        The sha256 in hexadecimal.
    """
    from .io import file_digest

    path = os.path.realpath(path)
    stamp = _stamp(os.stat(path))
    entries = {}
    if cache is not None:
        try:
            entries = json.loads(Path(cache).read_text())
        except (OSError, ValueError):
            entries = {}
        hit = entries.get(path)
        if isinstance(hit, dict) and hit.get("stamp") == stamp:
            return hit["sha256"]
    digest = file_digest(path)
    if cache is not None:
        entries[path] = {"stamp": stamp, "sha256": digest}
        try:
            Path(cache).parent.mkdir(parents=True, exist_ok=True)
            tmp = Path(f"{cache}.{os.getpid()}.tmp")
            tmp.write_text(json.dumps(entries, indent=0, sort_keys=True))
            os.replace(tmp, cache)  # several Snakemake processes parse at once: each writes whole, the last wins
        except OSError:
            pass  # a read-only project: the digest is computed again next time
    return digest


def measured_digests(
    paths: str | os.PathLike | Iterable[str | os.PathLike], measured: set[str], cache: str | os.PathLike | None = None
) -> dict[str, str]:
    """Return {path: sha256} of those of ``paths`` that are measured files.

    The parameter that makes a rule reading them run again when their content changes. Files the workflow writes
    itself (the rig's records, imported records) are left out: their rules' own inputs decide.

    Parameters
    ----------
    paths
        One path or several: a rule's input files.
    measured
        The paths of the measured files, as the config names them.
    cache
        The JSON file of digests (``file_sha256``; None: no cache).

    Returns
    -------
    digests : dict[str, str]
        The sha256 in hexadecimal of each of ``paths`` that is in ``measured`` and is a file, keyed by its path.
    """
    paths = [paths] if isinstance(paths, (str, os.PathLike)) else list(paths)
    return {str(p): file_sha256(p, cache) for p in paths if str(p) in measured and os.path.isfile(p)}
