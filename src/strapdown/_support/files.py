"""Atomic file output shared by every writer (private): a reader never sees a partly written file.

Every output is written to a temporary file (or, for the parts of a split run, a temporary folder) beside the
target and renamed onto it when complete, so an existing output is either replaced whole or left as it was.
What is left behind after a fault:

* an exception, KeyboardInterrupt (SIGINT), SIGTERM or SIGHUP: nothing.  The temporaries in use are removed;
  for the two signals a handler (installed while a temporary exists, main thread only) removes them, stops
  this process's worker processes (whose own handlers clean up after them) and then lets the signal take its
  default course, so the exit status still says "terminated by SIGTERM" (a pool's parent exits with status
  128 + the signal's number instead, through the interpreter's shutdown).
* kill -9, a power cut, a killed Dask worker: the temporaries stay, under names that say whose they are
  (``.<output>.strapdown-<host>-<pid>-<random>.tmp`` or ``.parts``).  The next run that writes the same output
  removes those of processes on this host that no longer exist; other files are never touched.
* a full disk (or a quota, or a file size limit): the temporary is removed and the error names the output.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import io
import os
import re
import secrets
import shutil
import signal
import socket
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

_LIVE: dict[str, bool] = {}  # temporaries in use: path -> is a folder
_LOCK = threading.RLock()  # re-entrant: the signal handler runs on the main thread, which may hold it
_HANDLED = (signal.SIGTERM, *((signal.SIGHUP,) if hasattr(signal, "SIGHUP") else ()))
_FULL = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG}
_SCRATCH = re.compile(r"\.strapdown-[A-Za-z0-9.-]+-\d+-[0-9a-f]{8}\.parts$")


@functools.cache
def _umask() -> int:
    """The process's umask, read once (reading it means setting it, which is not thread-safe to repeat)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


@functools.cache
def _host() -> str:
    """The machine's name as it goes into a temporary's name (letters, digits, dots and hyphens only)."""
    return re.sub(r"[^A-Za-z0-9.]", "-", socket.gethostname())[:64] or "host"


def _temp_name(target: Path, suffix: str) -> Path:
    return target.parent / f".{target.name}.strapdown-{_host()}-{os.getpid()}-{secrets.token_hex(4)}{suffix}"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process
        return True
    return True


def remove_stale(target) -> list[Path]:
    """Remove the temporaries for ``target`` left by processes of this host that no longer exist (kill -9).

    Only names of our own pattern are considered; a temporary of a live process or of another host (a shared
    folder on a cluster) is left alone.  Returns what was removed.
    """
    target = Path(target)
    pattern = re.compile(
        rf"^\.{re.escape(target.name)}\.strapdown-{re.escape(_host())}-(\d+)-[0-9a-f]{{8}}\.(tmp|parts)$"
    )
    removed = []
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return removed
    prefix = f".{target.name}.strapdown-"
    for entry in entries:
        if not entry.name.startswith(prefix):  # the cheap test first: a batch folder may hold many outputs
            continue
        m = pattern.match(entry.name)
        if not m or int(m.group(1)) == os.getpid() or _alive(int(m.group(1))):
            continue
        path = Path(entry.path)
        with contextlib.suppress(OSError):
            if m.group(2) == "parts" and entry.is_dir(follow_symlinks=False):
                shutil.rmtree(path)
            else:
                path.unlink()
            removed.append(path)
    return removed


def _remove(path: str, is_dir: bool) -> None:
    with contextlib.suppress(OSError):
        if is_dir:
            shutil.rmtree(path, ignore_errors=True)
        else:
            os.unlink(path)


def _on_signal(signum, frame) -> None:
    """SIGTERM/SIGHUP: remove the temporaries, stop our worker processes, then die of the signal as usual."""
    with _LOCK:
        live = list(_LIVE.items())
        _LIVE.clear()
    for path, is_dir in live:
        _remove(path, is_dir)
    try:
        import multiprocessing

        children = multiprocessing.active_children()
    except Exception:
        children = []
    for child in children:
        with contextlib.suppress(Exception):
            child.terminate()  # SIGTERM: a worker in an atomic write cleans up through this same handler
    for child in children:
        with contextlib.suppress(Exception):
            child.join(5)
    signal.signal(signum, signal.SIG_DFL)
    if children:
        # a pool's parent exits through the interpreter's shutdown, which releases the pool's semaphores (dying of
        # the signal, it left a "leaked semaphore" warning from the resource tracker); exit status 128 + signal
        raise SystemExit(128 + signum)
    os.kill(os.getpid(), signum)


def guard_signals() -> None:
    """Make SIGTERM and SIGHUP clean up (module notes) in a process that starts workers which write outputs.

    Called by the parent of a process pool: otherwise it dies at once of the signal, and its workers live on
    as orphans that finish and rename their outputs (or leave their temporaries).
    """
    _install()


def _install() -> None:
    """Install the handler for SIGTERM and SIGHUP where nobody else has one (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        return
    for sig in _HANDLED:
        with contextlib.suppress(ValueError, OSError):
            if signal.getsignal(sig) in (signal.SIG_DFL, None):
                signal.signal(sig, _on_signal)


@contextmanager
def _registered(path: Path, is_dir: bool) -> Iterator[None]:
    with _LOCK:
        _LIVE[str(path)] = is_dir
    _install()
    try:
        yield
    finally:
        with _LOCK:
            _LIVE.pop(str(path), None)


def _named(exc: OSError, target: Path) -> OSError:
    """A full disk's error, naming the output (the writer's own message names the temporary, or nothing)."""
    code = exc.errno if exc.errno in _FULL else errno.ENOSPC
    what = {errno.EDQUOT: "the disk quota is exceeded", errno.EFBIG: "the file size limit is reached"}
    reason = what.get(code, "no space left on the device")
    return OSError(code, f"cannot write {target}: {reason}; nothing was written (an existing file is unchanged)")


def _is_full(exc: BaseException) -> bool:
    """True for an out-of-space error, also when a library wraps it (h5py raises OSError with errno None)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and exc.errno in _FULL:
            return True
        text = str(exc).lower()
        if "no space left" in text or "file too large" in text or "quota exceeded" in text:
            return True
        exc = exc.__cause__ or exc.__context__
    return False


class GuardedFile(io.FileIO):
    """A binary file whose first failing write is recorded, and every later one pretended (for h5py).

    The HDF5 library does not survive a failed write: with a full disk it printed tracebacks while flushing
    its caches and then crashed the interpreter (SIGSEGV).  Given this file object (h5py's file-object
    driver), HDF5 never sees a failure; the writer calls :meth:`check` after closing, which raises the
    recorded error, and the temporary file, whose content is then garbage, is deleted by :func:`atomic_path`.
    """

    failure: OSError | None = None

    def _guard(self, call, *args, pretend=None):
        if self.failure is None:
            try:
                return call(*args)
            except OSError as exc:
                self.failure = exc
        return pretend

    def write(self, data) -> int:
        size = memoryview(data).nbytes
        if self.failure is None:
            view = memoryview(data).cast("B")
            done = 0
            while done < size and self.failure is None:  # FileIO may write part of it near the limit
                done += self._guard(super().write, view[done:], pretend=0) or 0
                if done < size and self.failure is None and not done:
                    self.failure = OSError(errno.ENOSPC, "no space left on the device")
        return size

    def truncate(self, size=None) -> int:
        return self._guard(super().truncate, size, pretend=size if size is not None else self.tell())

    def flush(self) -> None:
        self._guard(super().flush)

    def check(self) -> None:
        """Raise the first write error, if there was one."""
        if self.failure is not None:
            raise self.failure


@contextmanager
def _through_temp(path: Path) -> Iterator[Path]:
    """atomic_path for a target that is not a regular file (a device, a pipe).

    The output is made in a temporary directory (the target's own may not be writable: /dev) under the target's
    name, then copied into the target whole.
    """
    import tempfile

    with tempfile.TemporaryDirectory(prefix="strapdown-") as folder:
        tmp = Path(folder) / path.name
        yield tmp
        with open(tmp, "rb") as src, open(path, "wb") as dst:
            shutil.copyfileobj(src, dst)


@contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it onto ``path``, on any error delete it.

    The directory of ``path`` is created if missing.  The rename is atomic on one file system, which the
    temporary file shares with the target, so an existing ``path`` is either replaced whole or left as it was.
    The result gets the permissions a newly created file would have.  Stale temporaries of ``path`` from
    killed processes are removed first (module notes); an out-of-space error is re-raised as an OSError that
    names ``path``.
    """
    path = Path(path)
    if path.exists() and not path.is_file() and not path.is_dir():
        # a device or a pipe (-o /dev/null, /dev/stdout, a FIFO): written through once the output is whole, never
        # replaced; a rename onto /dev/null run as root turned the device into a regular file for the machine
        with _through_temp(path) as tmp:
            yield tmp
        return
    if _SCRATCH.search(path.parent.name) and not path.parent.is_dir():
        # a part for a scratch folder that its run has removed (interrupted): recreating it would leave it behind
        raise FileNotFoundError(errno.ENOENT, f"the scratch folder of an abandoned run is gone: {path.parent}")
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(path)
    tmp = _temp_name(path, ".tmp")
    with _registered(tmp, False):
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            os.close(fd)
            yield tmp
            os.chmod(tmp, 0o666 & ~_umask())
            os.replace(tmp, path)
        except BaseException as exc:
            tmp.unlink(missing_ok=True)
            if isinstance(exc, Exception) and _is_full(exc):
                raise _named(exc if isinstance(exc, OSError) else OSError(), path) from exc
            raise


@contextmanager
def scratch_dir(beside) -> Iterator[Path]:
    """Yield a new hidden directory beside the file ``beside`` (same file system); removed on exit, always.

    For intermediate files (the parts of a split run) that must be renamed or copied next to the output.
    Stale scratch folders of ``beside`` from killed processes are removed first.
    """
    beside = Path(beside)
    beside.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(beside)
    tmp = _temp_name(beside, ".parts")
    with _registered(tmp, True):
        try:
            tmp.mkdir(mode=0o700)
            yield tmp
        except Exception as exc:
            if _is_full(exc):
                raise _named(exc if isinstance(exc, OSError) else OSError(), beside) from exc
            raise
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
