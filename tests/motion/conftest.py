"""Fixtures of the motion tests: one IK solver per session (building the chain takes ~1 s)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def solver():
    from motion.ik import IKSolver

    return IKSolver()
