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
from typing import Iterator, Mapping


def record_blocks(cfg: Mapping) -> list[tuple[str, Mapping]]:
    """(config key, block) of every record the config names: the random test, then each load case."""
    blocks = [("random_test", cfg.get("random_test") or {})]
    return blocks + [(f"load_cases.{c}", lc or {}) for c, lc in (cfg.get("load_cases") or {}).items()]


def measured_records(cfg: Mapping) -> Iterator[tuple[str, Mapping]]:
    """(config key, block) of every record the config reads from a file (``record_blocks`` whose ``source`` is
    measured, with a ``file``)."""
    for where, block in record_blocks(cfg):
        if block.get("source", "rig") == "measured" and block.get("file"):
            yield where, block


def record_files(block: Mapping) -> list[tuple[str, str]]:
    """(key, path) of the files a measured record's block reads: its ``file``, and for CSV its sidecar YAML."""
    files = [("file", str(block["file"]))]
    if block.get("format") == "csv":
        from .importers import sidecar_path

        files.append(("sidecar", sidecar_path(block["file"], block.get("sidecar"))))
    return files


def _near_names(path: Path) -> str:
    """' (did you mean ...?)' for the closest names in the file's folder, or what the folder holds, or ''."""
    folder = path.parent
    if not folder.is_dir():
        return f" (the folder {str(folder)!r} does not exist either)"
    names = sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))
    close = difflib.get_close_matches(path.name, names, n=3, cutoff=0.6)
    if close:
        return f" (did you mean {', '.join(repr(str(folder / n)) for n in close)}?)"
    return f" ({str(folder)!r} holds {', '.join(names[:8])}{', ...' if len(names) > 8 else ''})" if names else ""


def missing_file_errors(cfg: Mapping, root: str | os.PathLike = ".") -> list[str]:
    """A message for every measured file (and CSV sidecar) the config names that does not exist, relative paths
    taken from ``root`` (the project directory, where Snakemake runs): the key, the path, where it was looked for,
    the closest names in its folder, and the fix."""
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
    """Two records read from one file: a copy-paste slip that would identify one record twice. Refused unless the
    later load case says ``allow_shared_file: true``; the random test and a load case never share a file."""
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
    """The sha256 of a file's content (hex). With ``cache`` (a JSON file), a digest is reused while the file's size,
    modification time, status-change time and inode are those it was computed at; any write to the file changes its
    status-change time, so a replaced file is read again whatever its modification time says."""
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


def measured_digests(paths, measured: set[str], cache: str | os.PathLike | None = None) -> dict[str, str]:
    """{path: sha256} of those of ``paths`` (one path or a list) that are measured files (in ``measured``): the
    parameter that makes a rule reading them run again when their content changes. Files the workflow writes
    itself (the rig's records, imported records) are left out: their rules' own inputs decide."""
    paths = [paths] if isinstance(paths, (str, os.PathLike)) else list(paths)
    return {str(p): file_sha256(p, cache) for p in paths if str(p) in measured and os.path.isfile(p)}
