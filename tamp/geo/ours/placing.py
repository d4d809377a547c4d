"""Moves into position taken without a window: the motion-aware planner's constructive moves.

On the unlimited table, Blocksworld's constructive moves (a clear block put into position: onto
its goal block when that block is in position and clear, or onto the table) start some shortest
plan (Gupta & Nau), and the task planner takes them without a window for big problems
(`task.domains.blocksworld.safe_moves`). On the bridged problem of a scene
(`tamp.geo.ours.bridge`) the table is capacity-one places, where that result no longer holds
in general (a shortest plan may park a block on a free goal place for a while), and the arm
may not be able to make the move at all. `placing_moves` keeps the moves that put a goal object
onto the very target its goal names (its goal cell, or its goal object in position and clear);
`next_placing` takes the one the arm's prices (`tamp.geo.ours.costs.GeoCosts`) leave open,
filling first the cells whose filling closes no other empty cell of their region (the packer's
placing order, `GeoCosts.closes`), then the cheapest. Where a place it fills is wanted later as
a parking spot or the hand's room, the windows and the fallback plan on from the state it
reached, where the placed objects may move again (the plan is then longer, and may take longer
to find).

Where every move of a plan is such a move (a tower built bottom up, objects sorted into their
regions' cells) no window runs: the receding windows plan only the decisions that need them
(objects moved out of the way and back, which object to clear first), and each of these moves
is bound by the full check like any planned move (`tamp.geo.ours.planner._bind`).
"""

from __future__ import annotations

from task.costs import IMPOSSIBLE
from task.domains.base import State
from task.domains.blocksworld import check_move as legal
from task.domains.blocksworld import in_position
from task.problem import TABLE, Move, Problem


def placing_moves(problem: Problem, state: State) -> list[Move]:
    """The legal moves, in entity order, that put a clear goal object not in position
    (`in_position`) onto the target its goal names: a place nothing stands on, or a goal
    object in position that is clear. A goal "on any place" (``TABLE``) names none: which
    place is a choice the windows make."""
    placed = in_position(problem, state)
    goal = dict(problem.goal)
    covered = set(state)
    out = []
    for x in problem.entities:
        y = goal.get(x)
        if y is None or y == TABLE or x in placed or x in covered or y in covered:
            continue
        if y in problem.entities and y not in placed:
            continue
        move = Move(x, y)
        if legal(problem, state, move) is None:
            out.append(move)
    return out


def next_placing(problem: Problem, state: State, costs) -> Move | None:
    """The placing move to take in ``state``: of `placing_moves` those ``costs`` (a
    `GeoCosts`) price below IMPOSSIBLE, the one closing the fewest empty cells of its region,
    then the cheapest; None when none is open."""
    best, key, closes = None, None, None
    for move in placing_moves(problem, state):
        price = costs.price_of(state, move)
        if price >= IMPOSSIBLE:
            continue
        closes = costs.closes(state) if closes is None else closes
        here = (closes.get(move.target, 0), price)
        if key is None or here < key:
            best, key = move, here
    return best
