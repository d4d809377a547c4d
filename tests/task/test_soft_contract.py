"""Contract tests run over every registered domain, on each domain's own sampler.

For the states of seeded random legal walks from ``domain.samples(seed)``:
- the soft step on one-hot states equals the crisp apply, column by column; illegal and padded
  columns carry zero mass and leave the state unchanged;
- rows stay distributions (or atom probabilities stay in [0, 1]) under soft actions;
- consistency is the identity on crisp states;
- the rollout loss passes gradcheck in float64 on soft logits;
- the oracle: a hand-written domain's move, replayed as its PDDL actions through the generic
  STRIPS lift and through crisp STRIPS apply, reaches ``to_atoms`` of its crisp successor.
"""

from __future__ import annotations

import functools
import random
from dataclasses import replace

import pytest
import torch

from task.config import PlannerConfig
from task.domains import GENERIC, get_domain, names
from task.domains.base import DomainBase, resolve_goal_loss
from task.problem import Action
from task.rollout import rollout
from task.soft import prod_others, transition
from task.symbolic import pddl_io, strips
from task.symbolic.generate import random_problem

DOMAINS = names()
HAND_WRITTEN = tuple(n for n in DOMAINS if n != GENERIC)
SEEDS = (0, 1)
WALK = 5  # random legal moves per walk; every state along it is a case


@functools.cache
def _cases(domain_name: str) -> tuple:
    """``(problem, state)`` for the initial state and every state along each seeded walk."""
    domain = get_domain(domain_name)
    out = []
    for seed in SEEDS:
        for problem in domain.samples(seed):
            rng = random.Random(f"{problem.name}:{seed}")
            state = domain.initial_state(problem)
            out.append((problem, state))
            for _ in range(WALK):
                legal = domain.legal_moves(problem, state)
                if not legal:
                    break
                state = domain.apply_move(problem, state, rng.choice(legal))
                out.append((problem, state))
    return tuple(out)


def _onehot(batch, row: int, col: int | None) -> torch.Tensor:
    """(1, N, A): action column ``col`` for ``row`` and STAY for every other row."""
    _, n, a = batch.action_mask.shape
    M = torch.zeros(1, n, a, dtype=torch.float64)
    M[0, :, -1] = 1.0
    if col is not None:
        M[0, row] = 0.0
        M[0, row, col] = 1.0
    return M


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_samples_walk_beyond_their_initial_states(domain_name):
    cases = _cases(domain_name)
    domain = get_domain(domain_name)
    assert len({domain.size(p) for p, _ in cases}) >= 2  # several sizes
    walked = [s for p, s in cases if s != get_domain(domain_name).initial_state(p)]
    assert len(walked) >= len(cases) // 2


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_soft_step_equals_crisp_apply_on_onehot_states(domain_name):
    domain = get_domain(domain_name)
    checked = {"legal": 0, "illegal": 0}
    for problem, state in _cases(domain_name):
        batch = domain.encode([problem], [state], torch.float64)
        F, (n, a) = batch.F0, batch.action_mask.shape[1:]
        for row in range(n):
            for col in range(a - 1):
                move = domain.decode(problem, row, col, n)
                allowed = bool(batch.action_mask[0, row, col])
                if move is None:  # padding: masked, or carries no mass
                    if allowed:
                        F1, g = domain.step(F, _onehot(batch, row, col), batch)
                        assert g.abs().sum().item() == 0.0 and torch.equal(F1, F)
                    continue
                reason = domain.check_move(problem, state, move)
                if not allowed:
                    assert reason is not None, f"legal {move} is masked"
                    continue
                F1, g = domain.step(F, _onehot(batch, row, col), batch)
                if reason is None:
                    after = domain.apply_move(problem, state, move)
                    expected = domain.encode([problem], [after], torch.float64).F0
                    assert torch.equal(F1, expected), move
                    assert g.sum().item() == 1.0 and g[0, row, col].item() == 1.0
                    checked["legal"] += 1
                else:
                    assert g.abs().sum().item() == 0.0, f"illegal {move} carries mass"
                    assert torch.equal(F1, F)
                    checked["illegal"] += 1
    assert min(checked.values()) >= 20, checked  # both branches, over many walked states


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_soft_states_stay_in_range_under_soft_actions(domain_name):
    domain = get_domain(domain_name)
    gen = torch.Generator().manual_seed(0)
    for problem, state in _cases(domain_name)[::3]:
        batch = domain.encode([problem], [state], torch.float64)
        F = batch.F0
        for _ in range(4):
            noise = torch.randn(batch.action_mask.shape, generator=gen, dtype=torch.float64)
            M = torch.softmax(torch.where(batch.action_mask, noise, -1e9), -1)
            F, g = domain.step(F, M, batch)
            assert (g >= 0).all() and (g <= 1 + 1e-12).all()
            assert (F >= -1e-12).all() and (F <= 1 + 1e-12).all()
            F = domain.consistency(F, batch)
            real = batch.entity_mask
            if domain.distributions:
                assert torch.allclose(F.sum(-1)[real], torch.ones_like(F[..., 0][real]))
            assert (F >= -1e-12).all() and (F <= 1 + 1e-12).all()


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_consistency_is_identity_on_crisp_states(domain_name):
    domain = get_domain(domain_name)
    for problem, state in _cases(domain_name):
        batch = domain.encode([problem], [state], torch.float64)
        assert torch.equal(domain.consistency(batch.F0, batch), batch.F0)
        assert domain.cycle_loss(batch.F0, batch).item() == 0.0


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_rollout_passes_gradcheck_in_float64_for_every_goal_loss(domain_name):
    domain = get_domain(domain_name)
    problem, state = next((p, s) for p, s in _cases(domain_name) if not domain.is_goal(p, s))
    batch = domain.encode([problem], [state], torch.float64)
    steps = torch.ones(1, 2, dtype=torch.bool)
    gen = torch.Generator().manual_seed(0)
    shape = (1, 2, *batch.action_mask.shape[1:])
    logits = torch.randn(shape, generator=gen, dtype=torch.float64).requires_grad_(True)
    for kind in ("default", *domain.goal_losses):
        config = replace(PlannerConfig(horizon=2), goal_loss=kind)
        assert resolve_goal_loss(domain, kind) in domain.goal_losses

        def loss(z, config=config):
            return rollout(domain, z, batch, steps, config).loss

        assert torch.autograd.gradcheck(loss, (logits,), eps=1e-6, atol=1e-5), kind


@pytest.mark.parametrize("domain_name", HAND_WRITTEN)
def test_hand_written_step_agrees_with_the_generic_lift_and_crisp_strips(domain_name):
    """One-hot oracle: domain step == lift step(s) == crisp STRIPS apply, on PDDL atoms."""
    domain, lift = get_domain(domain_name), get_domain(GENERIC)
    pddl_domain = pddl_io.parse_domain(domain.pddl_domain_text(), domain_name)
    checked, lifted = 0, {}
    for problem, state in _cases(domain_name)[::2]:
        if problem.name not in lifted:
            text = domain.to_pddl(problem)
            parsed = pddl_io.parse_problem(text, problem.name, pddl_domain)
            generic = lift.from_pddl(pddl_domain, parsed, pddl_io.object_order(text))
            lifted[problem.name] = parsed, generic, lift.to_atoms(generic, frozenset())
        parsed, generic, static = lifted[problem.name]
        for move in domain.legal_moves(problem, state)[:6]:
            atoms = domain.to_atoms(problem, state)
            expected = domain.to_atoms(problem, domain.apply_move(problem, state, move))
            crisp, soft = atoms, frozenset(atoms - static)
            # to_actions replays from init: translate the move from ``state`` as init
            for action in domain.to_actions(replace(problem, init=tuple(state)), [move]):
                action = Action(action.name.lower(), tuple(a.lower() for a in action.args))
                ground = strips.ground(pddl_domain, parsed, action)
                assert strips.applicable(crisp, ground), action
                crisp = strips.apply(crisp, ground)
                soft = _lift_step(lift, generic, soft, action)
            assert crisp == expected, move
            assert lift.to_atoms(generic, soft) == expected, move
            checked += 1
    assert checked >= 20


def _lift_step(lift, generic, state, action):
    """One lift step with ``action``'s column on the one-hot encoding of ``state``; checked
    against the lift's crisp apply. Returns the crisp successor."""
    batch = lift.encode([generic], [state], torch.float64)
    n, a = batch.action_mask.shape[1:]
    col = next(c for c in range(a - 1) if lift.decode(generic, 0, c, n) == action)
    F1, g = lift.step(batch.F0, _onehot(batch, 0, col), batch)
    assert g.sum().item() == 1.0, action
    after = lift.apply_move(generic, state, action)
    assert torch.equal(F1, lift.encode([generic], [after], torch.float64).F0), action
    return after


def test_competition_lets_only_one_entity_move():
    domain = get_domain("blocksworld")
    problem = random_problem(4, 1)
    batch = domain.encode([problem], [domain.initial_state(problem)], torch.float64)
    clear = [i for i, e in enumerate(problem.entities) if e not in domain.initial_state(problem)]
    M = _onehot(batch, clear[0], batch.n)  # clear block to the table
    if len(clear) > 1:
        M[0, clear[1]] = 0.0
        M[0, clear[1], batch.n] = 1.0  # a second full move in the same step
        _, g = transition(batch.F0, M, domain.soft_legality(batch.F0, batch))
        assert g.sum().item() == 0.0  # two certain movers cancel each other out


def test_prod_others_matches_loop():
    v = torch.rand(3, 5, dtype=torch.float64)
    out = prod_others(v)
    for i in range(5):
        others = torch.cat([v[:, :i], v[:, i + 1 :]], dim=1).prod(1)
        assert torch.allclose(out[:, i], others)


@pytest.mark.parametrize("name", DOMAINS)
def test_every_domain_inherits_the_optional_members_and_flags_its_own(name):
    """Every registered domain inherits `DomainBase`, so the planner calls its optional
    members directly; ``has_estimate`` and ``has_safe_moves`` say exactly whether the domain
    has its own, and without its own the estimate is the lower bound and it takes no safe
    or helpful moves."""
    domain = get_domain(name)
    own = vars(type(domain))
    assert isinstance(domain, DomainBase)
    assert domain.has_estimate == ("estimate" in own)
    assert domain.has_safe_moves == ("safe_moves" in own)
    problem = next(iter(domain.samples(0)))
    state = domain.initial_state(problem)
    if not domain.has_estimate:
        assert domain.estimate(problem, state) == domain.lower_bound(problem, state)
    if "helpful" not in own:
        assert domain.helpful(problem, state) == frozenset()
    if not domain.has_safe_moves:
        assert tuple(domain.safe_moves(problem, state)) == ()
    assert isinstance(dict(domain.planner_defaults), dict)
