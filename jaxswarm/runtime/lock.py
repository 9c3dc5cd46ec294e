"""One writing process at a time per folder: an advisory lock on a file in the folder.

The lock is ``fcntl.flock`` on ``FOLDER/.lock``. The kernel lets go of it when its process ends,
however it ends, so a killed writer leaves no lock behind: the next writer takes it over. The file
stays, holding the pid, host and start time of its last holder, which a second writer's error
names. Every :func:`lock_folder` of one process on one folder shares one lock (a store reopened
while a traceback still holds the first one, as a resume after an interrupt in a notebook does),
which the process lets go when the last of them is gone.
"""
from __future__ import annotations

import datetime
import fcntl
import json
import os
import socket
import threading
import weakref
from pathlib import Path

LOCK_NAME = ".lock"
"""The lock file's name inside the folder it locks."""

_held: dict[str, weakref.ref] = {}  # real path of a folder -> this process's FolderLock on it
_held_guard = threading.Lock()


class FolderLockedError(ValueError):
    """Another process holds the folder's lock."""


class FolderLock:
    """This process's hold on a folder's lock, let go when the last reference to it goes (or
    when the process ends).

    Attributes:
      path: the lock file.
    """

    def __init__(self, descriptor: int, path: Path):
        self.path = path
        self._close = weakref.finalize(self, os.close, descriptor)

    @property
    def held(self) -> bool:
        """Whether this process still holds the lock."""
        return self._close.alive


def lock_folder(folder) -> FolderLock:
    """Take the lock of ``folder`` (an existing directory) for this process, or share it if this
    process holds it already.

    Raises:
      FolderLockedError: another live process holds it; the message names the folder and the
        holder (its pid, host and since when, as it recorded them).
    """
    folder = Path(folder)
    key = os.path.realpath(folder)
    with _held_guard:
        reference = _held.get(key)
        lock = reference() if reference is not None else None
        if lock is not None and lock.held:
            return lock
        path = folder / LOCK_NAME
        descriptor = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _describe(os.pread(descriptor, 4096, 0))
            os.close(descriptor)
            raise FolderLockedError(f"{folder} is being written by another process ({holder}; "
                                    f"lock file {path})") from None
        except BaseException:
            os.close(descriptor)
            raise
        record = dict(pid=os.getpid(), host=socket.gethostname(),
                      since=datetime.datetime.now(datetime.timezone.utc).isoformat(
                          timespec="seconds"))
        os.ftruncate(descriptor, 0)
        os.pwrite(descriptor, json.dumps(record).encode(), 0)
        lock = FolderLock(descriptor, path)
        _held[key] = weakref.ref(lock)
        return lock


def process_alive(pid: int) -> bool:
    """Whether a process with id ``pid`` (> 0) runs on this host (a process of another user
    counts)."""
    if pid <= 0:
        raise ValueError(f"pid must be positive, got {pid}")
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _describe(recorded: bytes) -> str:
    """The holder as its lock file records it (``pid 12 on host since T``), or a note that it
    has not written itself there yet."""
    try:
        holder = json.loads(recorded.decode())
        return f"pid {holder['pid']} on {holder['host']} since {holder['since']}"
    except (ValueError, KeyError, TypeError):
        return "a process that has not recorded its pid yet"
