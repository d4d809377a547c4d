"""Argument types of the ``tamp`` subcommands: value parsers and validators for argparse.

Each turns one option's text into a value or raises a one-line usage error (an
`argparse.ArgumentTypeError`, or a `TampError` for an unknown simulator) naming what it expects;
the ``MAX_*`` bounds say what this machine can do. Parsing only: nothing here imports torch.
"""

from __future__ import annotations

import argparse
import os

from tamp.sim.base import SIMULATORS
from task.errors import TampError

MAX_PLACEMENT_M = 0.03  # `tamp.loop.LoopConfig.placements`: a block stays on its slot


def sim_list(text: str) -> tuple[str, ...]:
    """``--sim pybullet,mujoco`` as a tuple; TampError naming an unknown simulator."""
    sims = tuple(dict.fromkeys(t.strip() for t in text.split(",")))
    for name in sims:
        if name not in SIMULATORS:
            raise TampError(f"unknown simulator {name!r} (valid: {', '.join(SIMULATORS)})")
    return sims


# what the machine can do: a bound per option, each a one-line usage error beyond it
MAX_SEED = 2**32 - 1  # numpy's and torch's seeds; an episode seed is seed * 100_003 + k
MAX_WINDOW = 64  # moves per window (--horizon, --lookahead): beyond it no problem gets a plan
# sooner, and the (B, T, N, A) tensors outgrow the memory (1_000_000 hung before planning)
MAX_RESTARTS = 4096
MAX_ITERS = 100_000
MAX_BLOCKS = 200  # blocks of a random problem (--blocks)
MAX_BLUR = 64  # pixels; a radius beyond the image's size blurs nothing more (100000 hung)
MAX_COUNT = 1_000_000  # instances, images, nodes: more than any data set or a day of running
CORES = os.cpu_count() or 1
MAX_THREADS = 4 * CORES  # torch threads and worker processes (100000 threads crashed torch)


def bounded(low: int, high: int, what: str = "an integer"):
    """An argparse type: an integer in [``low``, ``high``], else one line naming the range."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"expected {what} in [{low}, {high}], got {text!r}")
        return value

    parse.__name__ = f"int_{low}_{high}"
    return parse


seed = bounded(0, MAX_SEED, "a seed")
threads = bounded(1, MAX_THREADS, f"a count of threads (4 x this machine's {CORES} cores)")
# planning's --threads default: one problem's tensors are small, and a second thread only waits
# for a core on a busy machine (BENCHMARKS.md: `tamp plan` 3x faster with 1 than with 2 under load)
PLAN_THREADS = "torch threads while planning (1; more help only on an idle machine)"
window = bounded(1, MAX_WINDOW, "a window length")


def positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    if value > MAX_COUNT:
        raise argparse.ArgumentTypeError(f"expected at most {MAX_COUNT}, got {text!r}")
    return value


def seconds(text: str) -> float:  # a positive number of seconds
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected seconds > 0, got {text!r}")
    return value


def seconds_or_off(text: str) -> float:  # seconds >= 0; 0 turns a phase off
    return 0.0 if text.strip() in ("0", "0.0") else seconds(text)


def nonnegative(text: str) -> int:
    return 0 if text.strip() == "0" else positive(text)


def positive_list(text: str, high: int = MAX_COUNT) -> tuple[int, ...]:
    try:
        values = tuple(int(t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated positive integers such as 1,3,5, got {text!r}"
        ) from None
    if not values or min(values) < 1 or max(values) > high:
        raise argparse.ArgumentTypeError(f"expected integers in [1, {high}], got {text!r}")
    return tuple(dict.fromkeys(values))


def window_list(text: str) -> tuple[int, ...]:
    return positive_list(text, MAX_WINDOW)


def block_counts(text: str) -> tuple[int, ...]:
    return positive_list(text, MAX_BLOCKS)


def radius_list(text: str) -> tuple[int, ...]:
    try:
        values = tuple(int(t) for t in text.split(","))
    except ValueError:
        values = (-1,)
    if not values or min(values) < 0 or max(values) > MAX_BLUR:
        raise argparse.ArgumentTypeError(
            f"expected radii in [0, {MAX_BLUR}] pixels such as 0,6, got {text!r}"
        )
    return tuple(dict.fromkeys(values))


radius = bounded(0, MAX_BLUR, "a blur radius in pixels")


def positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0.0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def placement(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0.0 <= value <= MAX_PLACEMENT_M:
        raise argparse.ArgumentTypeError(
            f"expected metres in [0, {MAX_PLACEMENT_M}] (a block stays on its slot), got {text!r}"
        )
    return value


def share(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {text!r}")
    return value


def name_list(what: str, valid: tuple[str, ...]):
    """A type: a comma-separated list of names from ``valid``, duplicates dropped."""

    def parse(text: str) -> tuple[str, ...]:
        names = tuple(dict.fromkeys(t.strip() for t in text.split(",") if t.strip()))
        if not names:
            raise argparse.ArgumentTypeError(f"no {what} named (valid: {', '.join(valid)})")
        for name in names:
            if name not in valid:
                raise argparse.ArgumentTypeError(
                    f"unknown {what} {name!r} (valid: {', '.join(valid)})"
                )
        return names

    return parse


def device(text: str) -> str:
    """``--device cpu|cuda|cuda:N``: a torch device this machine has (`task.config.DEVICES`);
    one line naming why not otherwise (a CPU-only torch, no visible GPU). torch is imported
    only for a CUDA device."""
    from task.config import device_problem

    try:
        why = device_problem(text)
    except TampError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    if why is not None:
        raise argparse.ArgumentTypeError(f"{text}: {why}")
    return text


BASELINES = ("us", "gn1")  # `tamp.bench.peers.slaney.BASELINES`, named without importing it


def baseline_list(text: str) -> tuple[str, ...]:
    """``--baselines us,gn1``: Slaney & Thiebaux's algorithms to run beside ours."""
    return name_list("baseline", BASELINES)(text)
