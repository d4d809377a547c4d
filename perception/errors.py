"""Errors about perception inputs: wrong image or box shapes, blocks that cannot be found."""

from __future__ import annotations

from task.errors import TampError


class PerceptionError(TampError):
    """An image, a box or a checkpoint does not fit the perception model."""
