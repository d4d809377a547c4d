"""Recovery and its vocabulary: tidying loose blocks and one line on why a move failed
(`describe`), including the give-up test `out_of_reach`. (The injected nudge, the
experimenter's fault, is `tamp.sim.faults.nudge`.)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from tamp.loop.execute import ExecutionResult
from tamp.outcome import Failure
from tamp.world.convert.from_poses import Reading
from task.problem import TABLE, Move


def tidy(
    reading: Reading,
    act: Callable[[Move, str], ExecutionResult],
    settle: Callable[[], None],
    say: Callable[[str], None],
) -> list[ExecutionResult]:
    """Recovery from an unreadable scene: put each loose block (leaning, on an edge) on a free
    table slot with an ordinary pick-and-place, ``act(move, label)``, letting the blocks
    ``settle`` after each. Returns the attempts; the caller observes again."""
    attempts = []
    for block in reading.loose:
        done = act(Move(block, TABLE), f"tidy {block}")
        attempts.append(done)
        say(f"tidy {block} onto the table: " + describe(done))
        settle()
    return attempts


def describe(result: ExecutionResult) -> str:
    """One line on why a move failed, e.g. ``move(a -> table): ik_infeasible (pre_grasp ...)``."""
    if result.ok:
        return f"{result.move}: ok"
    ev = result.evidence
    if result.failure is Failure.IK_INFEASIBLE:
        xyz = ", ".join(f"{v:.3f}" for v in ev.get("target_xyz", ()))
        detail = f"no IK solution for the {ev.get('waypoint')} waypoint at ({xyz}) m"
    else:
        detail = ", ".join(f"{k} {v}" for k, v in ev.items() if not isinstance(v, dict))
    return f"{result.move}: {result.failure.value} ({detail})"


def out_of_reach(moves: Sequence[ExecutionResult]) -> bool:
    """The last two attempts were the same move and both found no IK solution."""
    last = moves[-2:]
    return (
        len(last) == 2
        and all(r.failure is Failure.IK_INFEASIBLE for r in last)
        and last[0].move == last[1].move
    )
