"""Progress bars that suit where they are shown.

On a terminal a tqdm bar; elsewhere (a log file, a pipe, CI) a few plain lines,
so logs never fill with thousands of carriage-return updates.
"""

from __future__ import annotations

import sys

__all__ = ["progress_bar", "PlainProgress"]

#: Off a terminal, a plain line is printed each time this fraction of the work is done.
PLAIN_STEP = 0.25


def progress_bar(total: int, *, desc: str, unit: str = "it", file=None):
    """A tqdm bar when ``file`` (default stderr) is a terminal, else :class:`PlainProgress`.

    Both offer ``update(n)``, ``set_postfix(dict or **kw)`` and ``close()``.
    """
    file = sys.stderr if file is None else file
    if getattr(file, "isatty", lambda: False)():
        from tqdm.auto import tqdm
        return tqdm(total=total, desc=desc, unit=unit, leave=False, file=file)
    return PlainProgress(total, desc=desc, unit=unit, file=file)


class PlainProgress:
    """tqdm's interface, printing one line at 0%, every :data:`PLAIN_STEP`, and at the end.

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> bar = PlainProgress(4, desc="fit", file=out)
    >>> for _ in range(4):
    ...     bar.update(1)
    >>> bar.close()
    >>> print(out.getvalue().strip())
    fit: 0/4 it
    fit: 1/4 it
    fit: 2/4 it
    fit: 3/4 it
    fit: 4/4 it
    """

    def __init__(self, total: int, *, desc: str, unit: str = "it", file=None):
        self.total, self.desc, self.unit = int(total), desc, unit
        self.file = sys.stderr if file is None else file
        self.n = 0
        self.postfix = ""
        self._next = 0.0
        self._printed = -1
        self._line()

    def update(self, n: int = 1) -> None:
        self.n += n
        if self.total > 0 and self.n / self.total >= self._next:
            self._line()

    def set_postfix(self, ordered_dict=None, refresh: bool = True, **kwargs) -> None:
        items = {**(ordered_dict or {}), **kwargs}      # refresh: tqdm's, no effect here
        self.postfix = ", ".join(f"{k}={v}" for k, v in items.items())

    def close(self) -> None:
        if self._printed != self.n:
            self._line()

    def _line(self) -> None:
        extra = f" ({self.postfix})" if self.postfix else ""
        print(f"{self.desc}: {self.n}/{self.total} {self.unit}{extra}", file=self.file,
              flush=True)
        self._printed = self.n
        if self.total > 0:
            while self._next <= self.n / self.total:
                self._next += PLAIN_STEP
