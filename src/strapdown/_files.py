"""Atomic file output shared by every writer (private): a reader never sees a partly written file."""

from __future__ import annotations

import functools
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@functools.cache
def _umask() -> int:
    """The process's umask, read once (reading it means setting it, which is not thread-safe to repeat)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it onto ``path``, on any error delete it.

    The directory of ``path`` is created if missing.  The rename is atomic on one file system, which the
    temporary file shares with the target, so an existing ``path`` is either replaced whole or left as it was.
    The result gets the permissions a newly created file would have (``mkstemp`` makes it private).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextmanager
def scratch_dir(beside) -> Iterator[Path]:
    """Yield a new hidden directory beside the file ``beside`` (same file system); removed on exit, always.

    For intermediate files (the parts of a split run) that must be renamed or copied next to the output.
    """
    beside = Path(beside)
    beside.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=beside.parent, prefix=f".{beside.name}.", suffix=".parts"))
    try:
        yield tmp
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
