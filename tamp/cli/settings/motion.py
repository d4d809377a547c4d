"""``tamp bench motion`` at the edge: the parsed options turned once into `MotionSettings` (the
loop's `tamp.loop.LoopConfig`, the suite, the sweep and the output), and the recorded
configuration built from them.

`motion_settings` is the one function of this command that reads the argparse namespace (it
refuses ``--data`` with ``--blocks`` and ``--record`` without ``--out``, one line, exit 2);
below it (`tamp.cli.bench.arm.motion_command`) the benchmark takes `MotionSettings` only.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

from tamp.bench.official import default_data
from tamp.cli.recorded import loop_config, loop_dict, records_under_out
from tamp.cli.types import sim_list
from task.errors import TampError


@dataclass(frozen=True)
class BenchOutput:
    """Where a benchmark writes and how it shows progress: ``out`` (the folder of results.json;
    None: nothing written), ``json`` (the results on stdout), ``progress`` (a bar on stderr),
    ``record`` (a Rerun recording per episode under ``out``), and the command line ``argv``
    and planner ``device`` the results' machine record names (None: not given)."""

    out: str | None = None
    json: bool = False
    progress: bool = True
    record: bool = False
    argv: tuple[str, ...] | None = None
    device: str | None = None


@dataclass(frozen=True)
class MotionSettings:
    """What ``bench motion`` runs: closed-loop episodes with ``loop`` (its ``sim`` unused: each
    of ``sims`` runs them) on ``n`` PlanBench instances from ``data`` or, with ``blocks``,
    random problems of these sizes, seeded by ``seed``; ``workers`` processes or ``ray``
    (an address) run them."""

    loop: object  # tamp.loop.LoopConfig (imported with torch: not at parse time)
    sims: tuple[str, ...]
    n: int
    seed: int
    data: str | None
    blocks: tuple[int, ...] | None
    workers: int
    ray: str | None
    output: BenchOutput


def motion_settings(args: argparse.Namespace) -> MotionSettings:
    """``bench motion``: the options as `MotionSettings`, refused combinations first."""
    if args.blocks and args.data != str(default_data("blocksworld")):
        raise TampError("--data with --blocks: random problems read no data; drop one")
    records_under_out(args.record, args.out)
    argv = getattr(args, "argv", None)  # set by `tamp.cli.main` (absent when only parsed)
    output = BenchOutput(
        args.out,
        args.json,
        args.progress,
        args.record,
        None if argv is None else tuple(argv),
        args.device,
    )
    return MotionSettings(
        loop=loop_config(args),
        sims=tuple(sim_list(args.sim)),
        n=args.n,
        seed=args.seed,
        data=None if args.blocks else str(args.data),
        blocks=tuple(args.blocks) if args.blocks else None,
        workers=args.workers,
        ray=args.ray,
        output=output,
    )


def motion_record(settings: MotionSettings) -> dict:
    """The recorded configuration of ``bench motion``: the loop's settings
    (`tamp.cli.recorded.loop_dict`, less its one simulator) and the suite's and sweep's."""
    body = loop_dict(settings.loop)
    del body["sim"]
    return {
        **body,
        "sims": list(settings.sims),
        "n": settings.n,
        "seed": settings.seed,
        "data": settings.data,
        "blocks": None if settings.blocks is None else list(settings.blocks),
        "workers": settings.workers,
        "ray": settings.ray,
        "record": settings.output.record,
    }
