"""Atomic output files: the videos, study exports, cached study videos and their sidecars go to
a hidden temporary file beside the target and are renamed over it only when writing finished
without an error, so an interrupted or failing run never leaves a truncated file where a reader
expects a whole one (and an older whole file stays until it is replaced). MCAP recordings are
not written this way: they are written under their final name, a chunk flushed every second, so
a killed run keeps what it recorded (:mod:`gazebot.io.ros2.mcap_writer`).
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import TracebackType
from typing import TypeVar


def part_path(path: Path) -> Path:
    """A hidden temporary sibling of ``path``, unique to this process and call, keeping the
    suffix (muxers pick the container from it). Same folder, so the final rename is atomic."""
    return path.with_name(f".{path.stem}.part{os.getpid()}-{uuid.uuid4().hex[:8]}{path.suffix}")


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path to write ``path``'s content to; it replaces ``path`` when the
    block ends without an exception and is deleted in every case."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = part_path(path)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


_Self = TypeVar("_Self", bound="FinishOrAbort")


class FinishOrAbort:
    """A writer used as a context manager: :meth:`close` when the block ends normally,
    :meth:`abort` when it ends by an exception."""

    def close(self) -> object:
        """Finish the output."""
        raise NotImplementedError

    def abort(self) -> None:
        """Drop the output."""
        raise NotImplementedError

    def __enter__(self: _Self) -> _Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


class AtomicWriter(FinishOrAbort):
    """Base of the streaming writers: :attr:`path` is the target, :attr:`part` the temporary
    file being written. Subclasses finish their stream in :meth:`close` and then call
    :meth:`_commit`, and drop it in :meth:`abort`. As a context manager the file is committed
    when the block ends normally and aborted when it ends by an exception."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.part = part_path(self.path)

    def _commit(self) -> Path:
        try:
            os.replace(self.part, self.path)
        finally:
            self.part.unlink(missing_ok=True)
        return self.path

    def close(self) -> Path:
        """Finish the file and move it into place; returns :attr:`path`."""
        raise NotImplementedError

    def abort(self) -> None:
        """Stop writing and delete the temporary file; the target is left untouched."""
        raise NotImplementedError

