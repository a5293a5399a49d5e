"""Files the commands write (``--png``, ``--html``, ``--out``): checked before any work
starts, and written whole or not at all.

:func:`checked_output` refuses, with an :class:`InputError` naming the path and the
option, a target that is a folder or a symbolic link, lies in a missing folder or one
that cannot be written, or has a suffix the writer cannot produce: minutes of computation
must not end in a failed write. A symbolic link is refused rather than followed or
replaced, because writing through it changes a file the command was not given and
renaming over it silently turns the link into a file. :func:`atomic_output` writes to a
temporary file beside the target and renames it over the target (``os.replace``, atomic
on one file system), so that an interrupted or failed write leaves no truncated file.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

from assemblykit.errors import InputError

PNG_SUFFIXES = (".png",)
"""What ``--png`` writes (matplotlib picks the format from the suffix)."""

HTML_SUFFIXES = (".html", ".htm")
"""What ``--html`` writes."""


def checked_output(path: str | Path, option: str, suffixes: Sequence[str] = ()) -> Path:
    """``path`` as a :class:`Path` when a file can be written there; else
    :class:`InputError` naming ``path`` and ``option`` (module docstring). An empty
    ``suffixes`` accepts any name."""
    target = Path(path)
    source = str(path)
    if target.is_symlink():
        raise InputError("is a symbolic link: name the file itself", source=source, where=option)
    if target.is_dir():
        raise InputError("is a folder, not a file", source=source, where=option)
    if suffixes and target.suffix.lower() not in suffixes:
        raise InputError(
            f"unsupported file type {target.suffix or '(none)'!r} (expected {', '.join(suffixes)})",
            source=source,
            where=option,
        )
    folder = target.parent
    if not folder.is_dir():
        fault = "is not a folder" if folder.exists() else "does not exist"
        raise InputError(f"{str(folder)!r} {fault}", source=source, where=option)
    if not os.access(folder, os.W_OK | os.X_OK) or (
        target.exists() and not os.access(target, os.W_OK)
    ):
        raise InputError("cannot be written here (permission denied)", source=source, where=option)
    return target


def _mode_of(target: Path) -> int:
    """The permission bits ``target`` has, or a new file would get."""
    try:
        return stat.S_IMODE(target.stat().st_mode)
    except FileNotFoundError:
        mask = os.umask(0)
        os.umask(mask)
        return 0o666 & ~mask


@contextlib.contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` (same suffix, so writers that choose the format
    by suffix still do) that replaces ``path`` when the block ends without error and is
    removed otherwise. An operating-system failure becomes an :class:`InputError`
    naming ``path``."""
    target = Path(path)
    try:
        handle, name = tempfile.mkstemp(
            prefix=f".{target.name}.", suffix=target.suffix, dir=target.parent
        )
    except OSError as error:
        raise InputError(f"cannot write: {error.strerror}", source=str(path)) from None
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        # mkstemp makes the file private; the output gets the mode of the file it
        # replaces, or that of any new file (0666 less the umask)
        os.chmod(temporary, _mode_of(target))
        os.replace(temporary, target)
    except OSError as error:
        raise InputError(f"cannot write: {error.strerror}", source=str(path)) from None
    finally:
        temporary.unlink(missing_ok=True)
