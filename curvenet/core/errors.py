"""One exception family for the whole toolkit.

Every error that bad input can cause is a :class:`CurvenetError`; the CLI turns
it into one line and exit code 2. Anything else is an internal failure (exit 1).
"""

from __future__ import annotations

__all__ = [
    "CurvenetError",
    "SketchFormatError",
    "InvalidParameterError",
    "NetworkError",
    "MissingDependencyError",
    "OutputError",
]


class CurvenetError(Exception):
    """Base class of every error raised on bad input or an impossible request."""


class SketchFormatError(CurvenetError):
    """A file could not be read as a sketch, network or patch set.

    Parameters
    ----------
    message : str
        What is wrong, in a few words.
    path : str or os.PathLike, optional
        The file.
    line : int, optional
        1-based line number of the offending line.

    Examples
    --------
    >>> str(SketchFormatError("bad vertex", path="a.obj", line=3))
    'a.obj:3: bad vertex'
    """

    def __init__(self, message: str, *, path=None, line: int | None = None):
        self.message = message
        self.path = None if path is None else str(path)
        self.line = line
        where = ""
        if self.path is not None:
            where = self.path + (f":{line}" if line is not None else "") + ": "
        elif line is not None:
            where = f"line {line}: "
        super().__init__(where + message)


class InvalidParameterError(CurvenetError, ValueError):
    """A parameter has a value outside its meaningful range.

    The message names the parameter and the offending value.
    """


class NetworkError(CurvenetError):
    """A curve network or patch set is inconsistent (bad indices, open loops, ...)."""


class MissingDependencyError(CurvenetError, ImportError):
    """An optional feature needs a package that is not installed."""


class OutputError(CurvenetError):
    """An output cannot be written where asked: missing or read-only folder, the path is
    one of the inputs, or the write failed (disk full). The message names the requested
    path, never a temporary file."""
