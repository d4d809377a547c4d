"""Errors about robot descriptions: a missing URDF, an unknown joint or link."""

from __future__ import annotations

from task.errors import TampError


class RobotError(TampError):
    """A robot description or its files cannot be found or loaded."""
