"""Soft beliefs in the planner, and the soft -> crisp state decoding for perception."""

from __future__ import annotations

import pytest
import torch

from tamp.camera.states import all_states, complete_goal, most_likely_state
from task.config import PlannerConfig
from task.domains.blocksworld import DOMAIN, is_goal
from task.errors import ProblemError, TampError
from task.planner import plan
from task.problem import TABLE, Problem

THREE = Problem("three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("c", "b"),))


@pytest.mark.parametrize(("n", "count"), [(1, 1), (2, 3), (3, 13), (4, 73), (5, 501)])
def test_every_state_is_enumerated_once(n, count):
    states = all_states(n)
    assert states.shape == (count, n)
    assert len({tuple(s) for s in states.tolist()}) == count


def _onehot(problem: Problem, state) -> torch.Tensor:
    cols = [*problem.entities, TABLE]
    F = torch.zeros(problem.n, problem.n + 1)
    for x, s in enumerate(state):
        F[x, cols.index(s)] = 1.0
    return F


def test_most_likely_state_reads_a_confident_state_back():
    F = 0.9 * _onehot(THREE, THREE.init) + 0.1 / 4
    assert most_likely_state(THREE, F) == THREE.init


def test_most_likely_state_never_returns_two_blocks_on_one():
    # rows alone say: b on a (0.9), c on a (0.6); only one of them can be
    F = torch.tensor([[0.0, 0.05, 0.05, 0.9], [0.9, 0.0, 0.05, 0.05], [0.6, 0.1, 0.0, 0.3]])
    state = most_likely_state(THREE, F)
    assert state == (TABLE, "a", TABLE)  # c goes to its next best consistent support
    with pytest.raises(ProblemError, match="does not fit"):
        most_likely_state(THREE, F[:2])


def test_complete_goal_keeps_free_blocks_where_they_are():
    # goal: c on b; a stays on the table and b stays on a
    assert complete_goal(THREE) == (TABLE, "a", "b")
    clash = Problem("p", "blocksworld", ("a", "b", "c"), ("b", TABLE, TABLE), (("b", "a"),))
    done = complete_goal(clash)  # a cannot stay on b (that would be a cycle): it goes down
    assert done == (TABLE, "a", TABLE) and is_goal(clash, done)


class _Source:
    """Beliefs from one learnable logit table per problem (what perception would provide)."""

    def __init__(self, problem: Problem, learn: bool) -> None:
        F0 = _onehot(problem, problem.init)
        self.logits = torch.log(0.9 * F0 + 0.025).requires_grad_(learn)
        self.goal = _onehot(problem, complete_goal(problem))
        self.learn = learn
        self.calls = 0

    def __call__(self, indices, states):
        source = self

        class Window:
            lr = 0.05

            def compute(self):
                source.calls += 1
                F0 = torch.softmax(source.logits, -1)[None]
                return F0, source.goal[None], 0.1 * (F0 * F0).sum()[None]

            def parameters(self):
                return [source.logits] if source.learn else []

        return Window()


@pytest.mark.parametrize("learn", [False, True])
def test_beliefs_drive_the_window_and_only_learnable_ones_change(learn):
    source = _Source(THREE, learn)
    before = source.logits.detach().clone()
    config = PlannerConfig(iters=10, restarts=2)
    result = plan(THREE, config, seed=0, beliefs=source)
    assert result.solved  # decoded against the true state, goal reached
    assert source.calls >= config.iters  # recomputed at every Adam step
    changed = not torch.equal(before, source.logits.detach())
    assert changed is learn


def test_moves_that_only_the_beliefs_allow_are_never_decoded():
    # truth: b sits on a. The beliefs say b is on the table, so move(a -> c) looks legal and
    # reaches the goal in one step; in the true state it is illegal and must not be returned.
    problem = Problem("p", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"),))
    wrong = _onehot(problem, (TABLE, TABLE, TABLE))
    goal = _onehot(problem, ("c", TABLE, TABLE))

    class Wrong:
        lr = 0.1

        def compute(self):
            return wrong[None], goal[None], torch.zeros(1)

        def parameters(self):
            return []

    config = PlannerConfig(iters=30, restarts=4, max_windows=2)
    result = plan(problem, config, seed=0, beliefs=lambda i, s: Wrong())
    assert not result.solved and result.plan.moves == ()
    assert result.stats["windows"] == 2
    # the same planner on the true state solves it (the beliefs, not the planner, failed)
    assert plan(problem, config, seed=0).solved


def test_beliefs_of_the_wrong_shape_are_refused():
    class Bad:
        lr = 0.1

        def compute(self):
            return torch.zeros(1, 2, 3), torch.zeros(1, 2, 3), torch.zeros(1)

        def parameters(self):
            return []

    with pytest.raises(TampError, match="do not fit a batch"):
        plan(THREE, PlannerConfig(iters=2, restarts=1), beliefs=lambda i, s: Bad())


def test_domain_encoding_is_untouched_without_beliefs():
    batch = DOMAIN.encode([THREE], [THREE.init], torch.float32)
    assert torch.equal(batch.F0[0], _onehot(THREE, THREE.init))


class _Blind:
    """Adapted beliefs that read the current image as the goal scene: no move is ever worth
    making, so every window decodes nothing; ``fallback`` gives the true reading."""

    lr = 0.05
    crisp_states = None

    def __init__(self, problem: Problem, with_fallback: bool) -> None:
        self.problem, self.retried = problem, 0
        self.goal = _onehot(problem, complete_goal(problem))[None]
        if with_fallback:
            self.fallback = self._fallback

    def compute(self):
        return self.goal, self.goal, self.goal.new_zeros(1)

    def parameters(self):
        return []

    def _fallback(self, rows):
        assert list(rows) == [0]
        self.retried += 1
        blind = self

        class Frozen:
            lr, crisp_states = 0.0, None

            def compute(self):
                return (
                    _onehot(blind.problem, blind.state)[None],
                    blind.goal,
                    blind.goal.new_zeros(1),
                )

            def parameters(self):
                return []

        return Frozen()


@pytest.mark.parametrize("with_fallback", [False, True])
def test_a_window_stuck_under_adapted_beliefs_is_retried_frozen(with_fallback):
    made = []

    def source(indices, states):
        beliefs = _Blind(THREE, with_fallback)
        beliefs.state = states[0]
        made.append(beliefs)
        return beliefs

    result = plan(THREE, PlannerConfig(max_windows=4, restarts=4), seed=0, beliefs=source)
    assert result.solved == with_fallback
    assert sum(b.retried for b in made) == (len(made) if with_fallback else 0)


def test_window_beliefs_of_their_own_are_wrapped_once_with_their_optional_members():
    """Where a belief source enters the planner (`task.beliefs.belief_source`): each window's
    beliefs that do not inherit `WindowBeliefsBase` are wrapped, their own ``crisp_states`` and
    ``fallback`` kept; without them the defaults (the true states, no retry). Wrapping twice
    changes nothing."""
    from task.beliefs import WindowBeliefsBase, belief_source, window_beliefs

    problem = Problem("p", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))
    assert belief_source(None) is None
    plain = window_beliefs(_Blind(problem, with_fallback=False))
    assert isinstance(plain, WindowBeliefsBase) and plain.crisp_states is None
    assert plain.fallback([0]) is None and plain.lr == 0.05
    assert window_beliefs(plain) is plain
    blind = _Blind(problem, with_fallback=True)
    blind.state = problem.init
    blind.crisp_states = [problem.init]
    source = belief_source(lambda indices, states: blind)
    assert belief_source(source) is source
    wrapped = source([0], [problem.init])
    assert wrapped.crisp_states == [problem.init]
    assert torch.equal(wrapped.compute()[0], blind.compute()[0])
    frozen = wrapped.fallback([0])
    assert isinstance(frozen, WindowBeliefsBase) and blind.retried == 1
    assert frozen.crisp_states is None and frozen.parameters() == []
