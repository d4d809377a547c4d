"""Shared pytest fixtures: the project's own PDDL fixtures and the optional ../shared data."""

from __future__ import annotations

import os
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")  # headless: before anything imports mujoco

import pytest

REPO = Path(__file__).resolve().parents[1]
FIXTURES = REPO / "tests" / "task" / "fixtures"


@pytest.fixture
def planbench_dir() -> Path:
    """``../shared/data/planbench`` next to the repository; skips the test when it is absent."""
    path = REPO.parent / "shared" / "data" / "planbench"
    if not (path / "blocksworld" / "domain.pddl").is_file():
        pytest.skip(f"PlanBench data not found at {path} (needs the ../shared checkout)")
    return path


@pytest.fixture
def bw_domain_path() -> Path:
    """The project's own 4-operator blocksworld domain file (no ../shared needed)."""
    return FIXTURES / "blocksworld-4ops.pddl"
