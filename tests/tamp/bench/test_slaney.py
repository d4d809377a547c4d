"""Slaney & Thiebaux's US and GN1 (`tamp.bench.peers.slaney`): valid plans, US within twice
the optimum, GN1 never longer than US, and ``tamp bench random --baselines`` beside ours."""

from __future__ import annotations

import csv
import json

import pytest

from tamp.bench.peers import slaney
from tamp.bench.planning import Row, beside_best, best_known
from tamp.bench.summary import summarise
from tamp.cli import main
from task.domains import blocksworld
from task.domains.blocksworld import TABLE, with_slots
from task.errors import TampError
from task.problem import Move, Problem
from task.symbolic import pddl_io
from task.symbolic.generate import random_problem
from task.symbolic.search import optimal_moves
from task.symbolic.validate import validate

SMALL = [(n, seed) for n in (3, 4, 5, 6, 7) for seed in range(8)]


def _reaches_goal(problem: Problem, moves) -> bool:
    state = blocksworld.initial_state(problem)
    for move in moves:
        if blocksworld.check_move(problem, state, move) is not None:
            return False
        state = blocksworld.apply_move(problem, state, move)
    return blocksworld.is_goal(problem, state)


@pytest.mark.parametrize(("n", "seed"), SMALL)
def test_us_and_gn1_plan_validly_us_within_twice_the_optimum_gn1_within_us(n, seed):
    problem = random_problem(n, seed)
    us, gn1 = slaney.us(problem), slaney.gn1(problem)
    optimum = len(optimal_moves(problem))
    assert _reaches_goal(problem, us) and _reaches_goal(problem, gn1)
    assert optimum <= len(gn1) <= len(us) <= 2 * optimum


def test_the_plans_validate_against_the_pddl():
    problem = random_problem(6, 3)
    domain = blocksworld.DOMAIN
    parsed_domain = pddl_io.parse_domain(domain.pddl_domain_text())
    parsed = pddl_io.parse_problem(domain.to_pddl(problem), "<random>", parsed_domain)
    for name in ("us", "gn1"):
        actions = domain.to_actions(problem, slaney.run(name, problem).moves)
        assert validate(parsed_domain, parsed, actions).valid, name


def _problem(init: dict, goal: dict) -> Problem:
    names = tuple(sorted(init))
    return Problem(
        "hand", blocksworld.NAME, names, tuple(init[x] for x in names), tuple(goal.items())
    )


def test_gn1_makes_a_constructive_move_where_us_parks_first():
    # a on b, c alone; goal: a on c. US unstacks a (misplaced) to the table first, then
    # stacks it: 2 moves; GN1 sees that a can go onto c at once: 1 move
    problem = _problem({"a": "b", "b": TABLE, "c": TABLE}, {"a": "c"})
    assert slaney.us(problem) == (Move("a", TABLE), Move("a", "c"))
    assert slaney.gn1(problem) == (Move("a", "c"),)


def test_a_block_the_goal_leaves_free_is_misplaced_where_another_must_go():
    # c (no goal) sits on b, where the goal puts a; d (no goal) on a stays where it is
    problem = _problem({"a": TABLE, "b": TABLE, "c": "b", "d": "a"}, {"a": "b"})
    placed = slaney.in_position(problem, blocksworld.initial_state(problem))
    assert placed == {"a": False, "b": True, "c": False, "d": False}
    assert len(slaney.gn1(problem)) == 3  # c and d to the table, then a onto b


def test_a_deadlock_is_broken_by_the_move_that_lets_a_block_go_in_position():
    # a on e, h on c; goal a on c, h on a: neither can go in position. Parking a (first in
    # entity order) frees nothing anyone wants; parking h frees c for a. GN1 parks h: 3 moves
    # (the optimum); US parks both: 4
    problem = _problem({"a": "e", "c": TABLE, "e": TABLE, "h": "c"}, {"a": "c", "h": "a"})
    assert slaney.gn1(problem) == (Move("h", TABLE), Move("a", "c"), Move("h", "a"))
    assert len(slaney.us(problem)) == 4 and len(optimal_moves(problem)) == 3


def test_slotted_problems_and_unknown_baselines_are_refused():
    slotted = with_slots(random_problem(4, 0), ("s0", "s1", "s2", "s3"))
    with pytest.raises(TampError, match="plain Blocksworld"):
        slaney.us(slotted)
    with pytest.raises(TampError, match=r"unknown baseline 'us2' \(valid: us, gn1\)"):
        slaney.run("us2", random_problem(4, 0))


def test_the_summary_counts_each_baseline_against_ours_and_the_optimum():
    def row(length, us, gn1):
        return Row("i", 5, 8, None, 3, 0, length, "valid", 0.5, 1, None, None, us, 0.1, gn1, 0.3)

    s = summarise([row(10, 12, 10), row(8, 8, 8)], 3, 0, None, None)
    assert (s.us, s.us_length, s.gn1, s.gn1_length) == (2, 10.0, 2, 9.0)
    assert s.vs_us == pytest.approx((10 / 12 + 1) / 2) and s.vs_gn1 == 1.0
    assert s.us_ratio == pytest.approx(1.25) and s.us_s == 0.1 and s.gn1_s == 0.3
    bare = summarise([Row("i", 5, 8, None, 3, 0, 8, "valid", 0.5, 1)], 3, 0, None, None)
    assert bare.us is None and bare.gn1 is None  # the baselines did not run


def test_each_plan_is_set_beside_the_shortest_known_plan_of_its_instance():
    """No optimum known (big problems): the best known is the shortest of ours and the peers';
    a plan ours failed to find counts nowhere; nothing to compare without a peer."""

    def row(length, lama, us, gn1, status="valid"):
        return Row("i", 50, None, None, 3, 0, length, status, 1.0, 2, lama, 2.0, us, 0.1, gn1, 0.2)

    rows = [row(70, 150, 82, 68), row(60, 140, 66, 60), row(None, 120, 90, 80, "no_plan")]
    assert [best_known(r) for r in rows] == [68, 60, 80]
    s = summarise(rows, 3, 0, None, None)
    assert s.best == 1 and s.vs_best == pytest.approx((70 / 68 + 1) / 2)
    csv_row = beside_best(rows[0])
    assert csv_row["best_known"] == 68 and csv_row["x_best"] == pytest.approx(70 / 68)
    assert beside_best(rows[2])["x_best"] is None and beside_best(rows[2])["best_known"] == 80
    alone = Row("i", 50, None, None, 3, 0, 70, "valid", 1.0, 2)
    assert summarise([alone], 3, 0, None, None).vs_best is None  # only our own plan
    known = Row("i", 5, 8, None, 3, 0, 10, "valid", 0.5, 1)
    assert summarise([known], 3, 0, None, None).vs_best == pytest.approx(10 / 8)


def test_bench_random_prints_and_records_the_baselines_beside_ours(tmp_path, capsys):
    argv = ["bench", "random", "--blocks", "6", "--n", "2", "--restarts", "2", "--iters", "5"]
    argv += ["--baselines", "us,gn1", "--no-progress"]
    assert main([*argv, "--out", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert "US moves" in text and "ours/GN1" in text and "x best" in text
    with (tmp_path / "instances.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    for r in rows:  # our plan beside the shortest of the optimum, ours, US's and GN1's
        found = [r[k] for k in ("optimal", "length", "us_length", "gn1_length") if r[k]]
        best = min(int(k) for k in found)
        assert int(r["best_known"]) == best
        assert float(r["x_best"]) == pytest.approx(int(r["length"]) / best, abs=1e-4)
    body = json.loads((tmp_path / "results.json").read_text())
    assert body["config"]["baselines"] == ["us", "gn1"]
    sizes = body["by_size"]
    assert sizes[0]["us"] == 2 and sizes[0]["gn1"] == 2
    assert sizes[0]["gn1_length"] <= sizes[0]["us_length"]


def test_bench_planbench_takes_the_baselines_for_blocksworld_only(capsys, planbench_dir):
    data = ["--data", str(planbench_dir / "blocksworld")]
    assert main(["bench", "planbench", "--domain", "logistics", "--baselines", "us"]) == 2
    assert "--baselines plan Blocksworld only" in capsys.readouterr().err
    argv = ["bench", "planbench", *data, "--limit", "2", "--restarts", "2", "--iters", "5"]
    assert main([*argv, "--baselines", "gn1", "--no-progress", "--json"]) == 0
    body = json.loads(capsys.readouterr().out)
    assert body["config"]["baselines"] == ["gn1"] and body["summary"][0]["gn1"] == 2


def test_two_towers_each_wanting_the_others_base_are_a_deadlock_gn1_breaks():
    """a on b and c on d, the goal a on d and c on b: c is above d, which a must go above, and
    a above b, which c must go above: N(a, c) and N(c, a), a deadlock of two."""
    blocks, init = ("a", "b", "c", "d"), ("b", TABLE, "d", TABLE)
    problem = Problem("swap", "blocksworld", blocks, init, (("a", "d"), ("c", "b")))
    state = blocksworld.initial_state(problem)
    assert slaney.constructive(problem, state) == []
    assert slaney.deadlocked(problem, state) == {"a", "c"}
    plan = slaney.gn1(problem)
    assert _reaches_goal(problem, plan) and len(plan) == len(optimal_moves(problem)) == 3


def test_blocks_on_no_cycle_are_not_deadlocked():
    # a above b must go above c; nothing needs a block above a to move first: no cycle
    problem = Problem("chain", "blocksworld", ("a", "b", "c"), ("b", TABLE, TABLE), (("a", "c"),))
    state = blocksworld.initial_state(problem)
    assert slaney.deadlocked(problem, state) == set()
    assert slaney._on_cycles(["x", "y", "z"], {"x": ["y"], "y": ["z"], "z": ["y"]}) == {"y", "z"}
    assert slaney._on_cycles(["x"], {"x": ["x"]}) == {"x"}
