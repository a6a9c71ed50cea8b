"""Atomic file output: write to a temporary file beside the target, then rename.

An interrupted run never leaves a half-written file behind, and a failed write
(a read-only folder, a full disk) is reported naming the requested file, not the
hidden temporary one.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from .errors import OutputError

__all__ = ["atomic_path", "atomic_write_text", "check_output_path"]


def check_output_path(path, *, inputs=(), what: str = "output"):
    """Refuse an output path before any work is done; returns it as a ``Path``.

    Parameters
    ----------
    path : str or os.PathLike
        Where a file will be written.
    inputs : iterable of str or os.PathLike
        Files the user gave; the output must not be one of them (compared as
        resolved paths and with :func:`os.path.samefile`, so links count).
    what : str
        Name of the option, for the message (``"-o"``, ``"--preview"``).

    Raises
    ------
    OutputError
        The path is an existing folder, its folder does not exist or cannot be
        written, or it is one of the inputs.

    Notes
    -----
    Only the file is ever created: a missing folder is an error, never created.
    """
    p = Path(path)
    if p.is_dir():
        raise OutputError(f"{what} {p}: is a folder, not a file name")
    folder = p.parent if str(p.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"{what} {p}: folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{what} {p}: folder {folder} is not writable")
    for inp in inputs:
        if inp is None:
            continue
        if _same_file(p, Path(inp)):
            raise OutputError(f"{what} {p}: is the input file {inp}; "
                              "refusing to overwrite what you gave")
    return p


def _same_file(a: Path, b: Path) -> bool:
    # realpath, not Path.resolve: a symlink loop given as input is for its reader to refuse
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None):
    """Yield a temporary path in the target's folder; rename it onto ``path`` on success.

    Parameters
    ----------
    path : str or os.PathLike
        Final destination. Its folder must exist (it is never created).
    suffix : str, optional
        Suffix of the temporary file (defaults to the target's, so writers that
        pick a format by extension keep working).

    Raises
    ------
    OutputError
        The folder is missing or not writable, or writing failed (disk full,
        quota): the message names ``path``.

    Notes
    -----
    On an exception (including ``KeyboardInterrupt`` and the ``SystemExit`` the
    CLI raises on SIGTERM) the temporary file is removed and the target is left
    untouched.
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise OutputError(f"cannot write {path}: folder {directory} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix="." + path.name + ".",
                                   suffix=suffix or path.suffix, dir=directory)
    except OSError as err:
        raise OutputError(f"cannot write {path}: {err.strerror}") from None
    os.close(fd)
    try:
        yield Path(tmp)
        # mkstemp creates 0600; give the file the permissions a plain open() would
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except OSError as err:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise OutputError(f"cannot write {path}: {err.strerror or err}") from None
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
