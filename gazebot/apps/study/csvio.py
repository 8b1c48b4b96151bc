"""Reading and writing the study's CSV files with errors that name the file."""

from __future__ import annotations

import io
from pathlib import Path


def open_text(path: str | Path) -> io.StringIO:
    """The text of the UTF-8 file ``path`` (a leading byte-order mark is dropped) as a file
    object for :mod:`csv`. Text that is not UTF-8 raises ``ValueError`` naming the file and the
    offending byte (the bare ``UnicodeDecodeError`` names neither)."""
    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ValueError(
            f"{path}: not UTF-8 text (byte {exc.object[exc.start]:#04x} at offset {exc.start}); "
            "save the file as UTF-8"
        ) from None
    return io.StringIO(text, newline="")


def check_output_file(path: str | Path, what: str, suffix: str | None = None) -> Path:
    """``path`` as a Path if a file can be written there: not an existing folder, its parent not
    an existing file, and ending in ``suffix`` if given; else ``ValueError`` saying so."""
    path = Path(path)
    if path.is_dir():
        example = path / f"{what.replace(' ', '-')}{suffix or '.csv'}"
        raise ValueError(f"{what} output {path} is a directory; give a file path such as {example}")
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(f"{what} output {path}: {parent} is a file, not a directory")
            break
    if suffix is not None and path.suffix.lower() != suffix:
        raise ValueError(f"{what} output {path} must end in {suffix}")
    return path
