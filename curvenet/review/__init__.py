"""Patch review in front of a user: the session's suggestions, accepted or rejected.

In the terminal (:func:`run_interactive`) or on a local web page in the browser
(:class:`ReviewPage`, :func:`serve_review`; the ``[view]`` extra, viser, is imported
only when a page is made).
"""

from .terminal import run_interactive
from .web import ReviewPage, serve_review

__all__ = ["run_interactive", "ReviewPage", "serve_review"]
