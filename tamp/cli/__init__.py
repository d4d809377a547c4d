"""The ``tamp`` command line: argparse subcommands; parsing and printing only.

    tamp plan DOMAIN.pddl PROBLEM.pddl [--horizon 3 --restarts K --seed S --json --out plan.txt]
    tamp validate DOMAIN.pddl PROBLEM.pddl PLAN [--json]
    tamp example [--json --out DIR]
    tamp demo [--sim pybullet|mujoco --out out/demo]   (run --observe camera: make demo)
    tamp plan-images INIT.png GOAL.png [--image-scene cubes|latplan --perception frozen|optimised]
    tamp bench planbench [--data DIR --limit N --seeds 3 --horizon 1,3,5 --sequential N --out DIR]
    tamp bench random [--blocks 6,8,10 --n 50 --seed 0 --max-nodes 20000 --out DIR]
    tamp run [PROBLEM.pddl] [--sim pybullet|mujoco --inject drop:0.2 --seed S --out DIR]
    tamp bench latplan [--checkpoint FILE.pt --res 150x100,45x30 --modes state,frozen --seeds 3]
    tamp bench motion [--sim pybullet,mujoco --data DIR --n 100 --inject drop:0.2 --out DIR]
    tamp bench executability --plans FILE.csv|DIR [--sim pybullet,mujoco --n 20 --out DIR]

Exit codes: 0 success, 1 no plan or an invalid plan (an empty plan file that does not reach the
goal, in ``validate`` and ``run --plan`` alike), 2 usage error or bad input (one line on
stderr: ``tamp: error: ...``; argparse errors read ``tamp plan: error: ...``), 130 on Ctrl-C.
"""

from __future__ import annotations

import io
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from task.errors import TampError

__all__ = ["build_parser", "document_only", "main"]


def build_parser():
    """The ``tamp`` argument parser (`tamp.cli.parser`), imported when first asked for, so a
    Ctrl-C while it loads is caught by `main` like any other."""
    from tamp.cli.parser import build_parser as build

    return build()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``tamp`` command line; returns the exit code (Ctrl-C at any moment: one line,
    130; a benchmark first writes what it has done, marked partial)."""
    try:
        return _main(argv)
    except KeyboardInterrupt:
        print("tamp: interrupted", file=sys.stderr)
        return 130


def _main(argv: Sequence[str] | None) -> int:
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # argparse: --help exits 0, usage errors 2
        return exc.code if isinstance(exc.code, int) else 2
    args.argv = list(sys.argv[1:] if argv is None else argv)  # recorded in results.json
    try:
        with document_only(getattr(args, "json", False)):  # --json: stdout is the document
            return args.func(args)
    except TampError as exc:
        print(f"tamp: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # stdout closed early (e.g. piped into head): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


@contextmanager
def document_only(enabled: bool) -> Iterator[None]:
    """``--json``: stdout holds only the document. While the block runs (``enabled``), native
    writes on descriptor 1 (pybullet's EGL renderer prints ``Loaded EGL 1.5 after reload.``,
    ``GL_VENDOR=...``) go to stderr, and ``sys.stdout`` has a descriptor of its own onto the
    real stdout, so what the command prints (the document) is all stdout gets; both are
    restored afterwards. A no-op when ``sys.stdout`` is not a file descriptor's stream (e.g.
    captured by a test)."""
    try:
        fd = sys.stdout.fileno() if enabled else None
    except (AttributeError, OSError, ValueError):  # io.UnsupportedOperation: a stream in memory
        fd = None
    if fd is None:
        yield
        return
    stdout = sys.stdout
    stdout.flush()
    saved = os.dup(fd)  # the real stdout
    os.dup2(sys.stderr.fileno(), fd)
    sys.stdout = io.TextIOWrapper(
        io.FileIO(saved, "w", closefd=False), encoding=stdout.encoding, line_buffering=True
    )
    try:
        yield
    finally:
        try:
            sys.stdout.flush()
        finally:
            sys.stdout = stdout
            os.dup2(saved, fd)
            os.close(saved)
