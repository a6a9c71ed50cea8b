"""Shared fixtures: where the public data lives, and a skip when it is absent."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

DATA_DIR = Path(os.environ.get("CURVENET_DATA",
                               Path(__file__).resolve().parents[1].parent / "shared" / "data"))


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """``../shared/data`` (or ``$CURVENET_DATA``); skips the test when it is missing."""
    if not DATA_DIR.is_dir():
        pytest.skip(f"public data not found at {DATA_DIR} (set CURVENET_DATA)")
    return DATA_DIR
