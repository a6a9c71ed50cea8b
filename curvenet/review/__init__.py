"""Patch review in front of a user: the session's suggestions, accepted or rejected."""

from .terminal import run_interactive

__all__ = ["run_interactive"]
