"""Patch review in the terminal: one-key answers to the session's suggestions.

:func:`run_interactive` drives a :class:`~curvenet.cycles.session.PatchSession` from
any pair of text streams, so it works on a terminal and with answers piped on stdin;
with ``preview`` it renders each suggestion highlighted to a PNG
(:func:`curvenet.view.render_preview`).

References
----------
Abbasinejad, Joshi, Amenta 2011, Sec. 5 (the interactive phase).
"""

from __future__ import annotations

import sys

from ..core.errors import InvalidParameterError, NetworkError, OutputError
from ..cycles.session import PatchSession
from ..model.patchset import PatchSet
from ..view.preview import render_preview

__all__ = ["run_interactive"]


_HELP = ("commands: [l]ist patches, [d]elete a patch, [c]losing suggestions, "
         "[r]eplacement suggestions, [u]ndo, [s]ave, [q]uit, [h]elp")


def _ask(prompt, input, output) -> str | None:
    output.write(prompt)
    output.flush()
    line = input.readline()
    if not line:
        return None
    return line.strip()


def _review(session, suggestions, input, output, preview) -> bool:
    """Offer each suggestion: [a]ccept, [r]eject, [n]ext, [q]uit. False on end of input.

    A rejected suggestion is followed by its alternatives (the next cycles through the
    same curves, :meth:`~curvenet.cycles.session.PatchSession.alternatives_to`) not
    offered yet.
    """
    if not suggestions:
        output.write("no suggestions\n")
        return True
    queue = list(suggestions)
    offered = {s.edges for s in queue}
    j = 0
    while j < len(queue):
        s = queue[j]
        j += 1
        output.write(f"  #{j} {s.describe()}\n")
        if preview:
            render_preview(preview, network=session.network, patches=session.patches,
                           highlight=[list(s.edges)], title=f"{s.kind} #{j}")
            output.write(f"  preview: {preview}\n")
        ans = _ask("  [a]ccept [r]eject [n]ext [q]uit > ", input, output)
        if ans is None:
            return False
        key = ans[:1].lower()
        if key == "a":
            session.accept(s)
            output.write(f"  accepted (patch {len(session.patches) - 1})\n")
            return True
        if key == "r":
            session.reject(s)
            alts = [a for a in session.alternatives_to(s.edges) if a.edges not in offered]
            offered |= {a.edges for a in alts}
            queue[j:j] = alts
            output.write(f"  rejected; {len(alts)} alternatives through its curves next\n"
                         if alts else "  rejected\n")
        elif key == "q":
            return True
    return True


def run_interactive(patchset: PatchSet, *, input=sys.stdin, output=sys.stdout, preview=None,
                    backend: str = "galois") -> PatchSet:
    """Edit a patch set from the terminal; returns the final patch set.

    Parameters
    ----------
    patchset : PatchSet
    input, output : text streams
        Answers are read one line at a time and only the first character of
        an answer counts, so piped answers work (``printf 'c\\na\\nq\\n' | ...``).
    preview : str or os.PathLike, optional
        PNG written (overwritten) for every suggestion shown, the suggestion
        highlighted (:func:`curvenet.view.preview.render_preview`).
    backend : {"galois", "bitset"}

    Returns
    -------
    PatchSet
        The patches when the user quits (``q`` or end of input).

    Notes
    -----
    Main prompt keys: ``l`` list, ``d`` delete (then the patch number; the cycles
    through its curves that could take its place are offered first), ``c``
    closing suggestions, ``r`` replacement suggestions, ``u`` undo, ``s`` save
    (then a path), ``q`` quit, ``h`` help. Each suggestion is answered with
    ``a`` accept, ``r`` reject (its alternatives through the same curves are offered
    next), ``n`` next, ``q`` back to the main prompt.
    """
    session = PatchSession(patchset, backend=backend)
    output.write(f"{len(session.patches)} patches, rank {session.rank()} of "
                 f"{session.full_rank}\n{_HELP}\n")
    while True:
        ans = _ask("patches> ", input, output)
        if ans is None:
            break
        key = ans[:1].lower()
        if key == "q":
            break
        if key == "l":
            for i, p in enumerate(session.patches):
                output.write(f"  {i}: {len(p.edges)} edges {list(p.edges)} ({p.source})\n")
        elif key == "d":
            arg = ans[1:].strip() or _ask("  patch number > ", input, output)
            if arg is None:
                break
            try:
                alts = session.alternatives_to(int(arg))
                sugg = session.delete(int(arg))
            except (ValueError, InvalidParameterError) as err:
                output.write(f"  cannot delete {arg!r}: {err}\n")
                continue
            output.write(f"  deleted; rank {session.rank()} of {session.full_rank}\n")
            if not _review(session, alts or sugg, input, output, preview):
                break
        elif key == "c":
            if not _review(session, session.closing_suggestions(), input, output, preview):
                break
        elif key == "r":
            if not _review(session, session.replacement_suggestions(), input, output, preview):
                break
        elif key == "u":
            output.write("  undone\n" if session.undo() else "  nothing to undo\n")
        elif key == "s":
            path = ans[1:].strip() or _ask("  save to > ", input, output)
            if path is None:
                break
            try:
                session.save(path)
                output.write(f"  saved {path}\n")
            except (OSError, NetworkError, OutputError) as err:
                output.write(f"  cannot save {path!r}: {err}\n")
        else:
            output.write(_HELP + "\n")
    return session.patchset
