"""Fault injection to exercise recovery: drops in transit, nudged blocks, noisy observations.

``Injection.parse("drop:0.2,nudge:0.1,noise:0.05")`` gives each kind a probability per move
(``noise``: per observation). Draws come from a seeded ``numpy`` generator owned by the
episode, so an episode is reproducible from its seed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from task.errors import TampError

KINDS = ("drop", "nudge", "noise")


@dataclass(frozen=True)
class Injection:
    """Probabilities of each fault. ``drop``: open the gripper at a random point of the
    transit. ``nudge``: push the just-placed block ``nudge_m`` sideways. ``noise``: add
    Gaussian noise of ``noise_sigma`` m to every observed block position."""

    drop: float = 0.0
    nudge: float = 0.0
    noise: float = 0.0
    nudge_m: float = 0.06
    noise_sigma: float = 0.01
    drop_moves: tuple[int, ...] = ()  # move indices that always drop (reproducible tests)
    nudge_moves: tuple[int, ...] = ()  # move indices whose placed block is always nudged

    @classmethod
    def parse(cls, text: str | None) -> Injection:
        """``"drop:0.2,nudge:0.1"`` -> Injection(drop=0.2, nudge=0.1); None or '' -> none."""
        if not text:
            return cls()
        values = {}
        for part in text.split(","):
            kind, sep, prob = part.strip().partition(":")
            if kind not in KINDS or not sep:
                raise TampError(f"bad fault {part.strip()!r}: use KIND:P with KIND in {KINDS}")
            try:
                p = float(prob)
            except ValueError:
                raise TampError(f"bad probability {prob!r} for fault {kind!r}") from None
            if not 0.0 <= p <= 1.0:
                raise TampError(f"fault probability must be in [0, 1], got {kind}:{p}")
            values[kind] = p
        return cls(**values)

    def __str__(self) -> str:
        parts = [f"{k}:{getattr(self, k):g}" for k in KINDS if getattr(self, k) > 0]
        return ",".join(parts) or "none"


def draw(rng: np.random.Generator, probability: float) -> bool:
    """One Bernoulli draw; always consumes a number so episodes stay aligned across settings."""
    return bool(rng.random() < probability)
