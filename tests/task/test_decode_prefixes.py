"""Ranking a window by its best prefix (`task.decode`): cut where moves stop paying off, buried
moves below parking ones, parking counted as free on request."""

from __future__ import annotations

import torch

from task.decode import DecodeRule, WindowStart, decode_best, decode_row
from task.domains import get_domain
from task.problem import Move, Problem

BW = get_domain("blocksworld")
# a on b; c and d on the table; goal: the tower b-c-a. Lower bound 2 (a and c must move), optimum
# 3 (a parks on the table, c onto b, a onto c).
TOWER = Problem(
    "p",
    "blocksworld",
    ("a", "b", "c", "d"),
    ("b", "table", "table", "table"),
    (("a", "c"), ("c", "b")),
)


PLAIN, PREFIX = DecodeRule(0.3), DecodeRule(0.3, prefix=True)  # one restart row


def _gates(*moves: Move) -> torch.Tensor:
    """One confident step per move: (T, N, Y)."""
    gates = torch.zeros(len(moves), TOWER.n, TOWER.n + 1)
    for t, move in enumerate(moves):
        gates[t, TOWER.entities.index(move.entity), TOWER.index(move.target)] = 0.9
    return gates


def test_a_window_is_cut_to_its_best_prefix():
    state = BW.initial_state(TOWER)
    moves = (Move("a", "table"), Move("c", "b"), Move("d", "c"))  # the last one wastes a move
    assert decode_row(BW, WindowStart(TOWER, state), _gates(*moves), 0.0, PLAIN).moves == moves
    cut = decode_row(BW, WindowStart(TOWER, state), _gates(*moves), 0.0, PREFIX)
    assert cut.moves == moves[:2] and cut.remaining == 1 and cut.buried == 0
    assert cut.state == BW.apply_move(TOWER, BW.apply_move(TOWER, state, moves[0]), moves[1])
    worse = decode_row(BW, WindowStart(TOWER, state), _gates(Move("d", "c")), 0.0, PREFIX)
    assert worse.remaining == 3 and worse.buried == 1  # d on c, which must move: d must too


def test_buried_moves_rank_below_parking_ones():
    state = BW.initial_state(TOWER)
    gates = torch.stack([_gates(Move("a", "d")), _gates(Move("a", "table"))])  # (R, T, N, Y)
    losses = torch.tensor([0.0, 1.0])  # the buried restart has the lower soft objective
    plain = decode_best(BW, [WindowStart(TOWER, state)], gates, losses, DecodeRule(0.3, 2))[0]
    assert plain.moves == (Move("a", "d"),)  # same moves + bound: the soft objective decides
    ranked = decode_best(
        BW, [WindowStart(TOWER, state)], gates, losses, DecodeRule(0.3, 2, prefix=True)
    )[0]
    assert ranked.moves == (Move("a", "table"),) and ranked.buried == 0


def test_parking_is_free_only_when_asked():
    state = BW.initial_state(TOWER)
    park = _gates(Move("a", "table"))
    assert decode_row(BW, WindowStart(TOWER, state), park, 0.0, PREFIX).estimated == 2
    free = decode_row(BW, WindowStart(TOWER, state, park=True), park, 0.0, PREFIX)
    assert (free.remaining, free.estimated) == (2, 1)  # the bound, less one parking move


def test_parking_is_free_per_problem_when_asked_per_problem():
    state = BW.initial_state(TOWER)
    gates = torch.stack([_gates(Move("a", "table"))] * 2)  # one problem, two restarts
    rule = DecodeRule(0.3, 2, prefix=True)
    (kept,) = decode_best(BW, [WindowStart(TOWER, state, park=False)], gates, torch.zeros(2), rule)
    (free,) = decode_best(BW, [WindowStart(TOWER, state, park=True)], gates, torch.zeros(2), rule)
    assert (kept.estimated, free.estimated) == (2, 1)
