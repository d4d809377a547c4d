"""The logistics domain: crisp moves, soft gates, a shaped goal potential, moves <-> actions,
and seeded random problems (`samples`, named as PlanBench names them: a0, c0, t0, l0-0, p0;
l<c>-0 is city c's airport). The static map and routes are `task.domains.logistics_map`;
problem PDDL in and out `task.domains.logistics_pddl`.

Rows are packages, trucks and airplanes; targets are those entities and the locations (fixed
targets). ``move(p -> v)`` loads a package into a vehicle at its location, ``move(p -> l)``
unloads it at ``l``, ``move(v -> l)`` drives a truck in its city or flies an airplane between
airports; nothing targets a package; a package in a vehicle moves with it (its support is the
vehicle). `encode` masks all other columns; gates are product t-norms; consistency is row
normalisation (unlimited capacity); no cycle term. A move is one ``logistics-strips`` action.

Departure from `relational_step`: the one-move competition is by priority, q(x) = prod_{x' < x}
(1 - rho(x')) (packages, trucks, airplanes), not prod_{x' != x}: with up to 13 rows many have
a useful move at once, each saturates it, q -> 0 for all and gradients vanish (instance-201's
first window: 1 of 16 restarts decoded a move; 16 of 16 by priority). One mover: they agree.

Goal losses: ``potential`` (default), the expected remaining actions: per goal package over its
soft support, the loads, unloads and moves of its shortest static route, plus per leg the soft
absence of a suitable vehicle where it starts (in a vehicle: that vehicle's absence where it
should unload); per vehicle goal 1 - F[v, g]. Plans are 3-41 actions and a window 3-5 moves, so
the paper's ``atoms`` CE on P(at p g) (the second kind) has no gradient for most of a plan.
"""

from __future__ import annotations

import functools
import math
import random
from collections.abc import Sequence

import torch
from torch import Tensor

from task.domains import logistics_map as lm
from task.domains import logistics_pddl as lp
from task.domains.base import (
    INF,
    DomainBase,
    SoftBatch,
    encode_supports,
    relational_decode,
    zero_cycle_loss,
)
from task.domains.match.renaming import user_actions, user_atoms
from task.errors import ProblemError, one_of
from task.problem import Action, Move, Problem
from task.soft import goal_cross_entropy, row_normalise

State = tuple[str, ...]
GOAL_LOSSES = ("potential", "atoms")  # the first is the default
ROW = {"package": 0, "truck": 1, "airplane": 2}
UNREACHABLE = 100.0  # potential of a support from which a goal cannot be reached


def initial_state(problem: Problem) -> State:
    return tuple(problem.init)


def check_move(problem: Problem, state: State, move: Move) -> str | None:
    """None if ``move`` is legal in ``state``, else a one-line reason (ProblemError: unknown)."""
    d, fixed, x, y = problem.data, problem.fixed, move.entity, move.target
    s, kind = state[lm.entity(problem, x)], d.kind(x)
    if y not in problem.targets:
        raise ProblemError(f"unknown vehicle or location {one_of(y, problem.targets)}")
    if x == y or d.kind(y) == "package":
        return f"{x} cannot go into {y} (targets: vehicles and locations)"
    if kind == "package" and y in fixed:
        if s in fixed:
            return f"{x} is not in a vehicle (it is at {s})"
        at = lm.where(problem, state, s)
        return None if at == y else f"{x} is in {s}, which is at {at}, not {y}"
    if kind == "package":
        if s not in fixed:
            return f"{x} is in {s}; unload it first"
        at = lm.where(problem, state, y)
        return None if at == s else f"{x} is at {s} but {y} is at {at}"
    if y not in fixed:
        return f"{kind} {x} can only go to a location, not {y}"
    if s == y:
        return f"{x} is already at {y}"
    if kind == "truck" and fixed.index(y) not in lm.reach(problem, x):
        return f"{y} is in {d.city[fixed.index(y)]}; truck {x} stays in its city"
    if kind == "airplane" and y not in d.airports:
        return f"{y} is not an airport {one_of(y, d.airports)}"
    return None


def apply_move(problem: Problem, state: State, move: Move) -> State:
    """The state after ``move``; raises ProblemError if it is illegal."""
    reason = check_move(problem, state, move)
    if reason is not None:
        raise ProblemError(f"illegal {move}: {reason}")
    i = lm.entity(problem, move.entity)
    return (*state[:i], move.target, *state[i + 1 :])


def legal_moves(problem: Problem, state: State) -> list[Move]:
    """Every legal move in ``state``, entities in order, targets in order."""
    moves = [Move(x, y) for x in problem.entities for y in problem.targets if y != x]
    return [m for m in moves if check_move(problem, state, m) is None]


def is_goal(problem: Problem, state: State) -> bool:
    return all(state[lm.entity(problem, x)] == loc for x, loc in problem.goal)


def lower_bound(problem: Problem, state: State) -> float:
    """Admissible: the loads/unloads each goal package needs (2 per route leg, 1 to leave a
    vehicle) plus per vehicle kind the distinct locations one must arrive at (one move each): a
    truck where a package waits off an airport with none there, at a goal off an airport; for a
    package changing city an airplane at its city's only airport (unless one is there) and the
    goal city's, a truck at its city's airport (unless the package is there); one move per unmet
    vehicle goal. `INF` when a package's goal is unreachable."""
    d: lm.LogisticsData = problem.data
    dist, idx = lm.routes(d, problem.fixed)[0], {x: j for j, x in enumerate(problem.fixed)}
    at = {x: lm.where(problem, state, x) for x in problem.entities}
    present = {(d.kind(v), at[v]) for v in (*d.trucks, *d.airplanes)}
    ports = {c: [a for a in d.airports if d.city[idx[a]] == c] for c in d.cities}
    need, goals, actions = {"truck": set(), "airplane": set()}, {"truck": [], "airplane": []}, 0.0
    for x, g in problem.goal:
        s, gj = state[lm.entity(problem, x)], idx[g]
        goals[d.kind(x)] = goals.get(d.kind(x), []) + ([] if s == g else [g])
        if d.kind(x) != "package" or s == g:
            continue
        if s in idx:
            actions += 2 * dist[idx[s]][gj]
            if s not in d.airports and ("truck", s) not in present:
                need["truck"].add(s)
        else:
            actions += 1 + 2 * min(dist[u][gj] for u in lm.reach(problem, s))
        if g not in d.airports and not (d.kind(s) == "truck" and at[s] == g):
            need["truck"].add(g)
        here, there = d.city[idx[at[x]]], d.city[gj]
        if here != there and d.kind(s) != "airplane" and len(ports[here]) == 1:
            need["airplane"] |= {a for a in ports[here] if ("airplane", a) not in present}
            need["truck"] |= {a for a in ports[here] if a != at[x]}
        if here != there and len(ports[there]) == 1:
            need["airplane"] |= set(ports[there])
    moves = sum(len(goals[k]) + len(need[k] - set(goals[k])) for k in need)
    return INF if math.isinf(actions) else actions + moves


def to_actions(problem: Problem, moves: Sequence[Move], strict: bool = True) -> tuple[Action, ...]:
    """One logistics-strips action per move, replayed from init (ProblemError if illegal).
    ``strict=False`` translates an illegal move as it stands, for a validator to name (a vehicle
    sent where it is becomes a no-op drive or flight, which PDDL allows), and replays on. Unknown
    names and moves no action expresses (a truck into a package) raise either way."""
    d: lm.LogisticsData = problem.data
    state, out = initial_state(problem), []
    for move in moves:
        i, (x, y) = lm.entity(problem, move.entity), (move.entity, move.target)
        if check_move(problem, state, move) and strict:  # unknown names raise either way
            apply_move(problem, state, move)  # ProblemError: illegal
        kind, ky, s = d.kind(x), d.kind(y), state[i]
        if kind == "package" and ky in ("truck", "airplane"):
            loc = s if s in problem.fixed else lm.where(problem, state, y)
            out.append(Action(f"load-{ky}", (x, y, loc)))
        elif kind == "package" and y in problem.fixed:
            there = [v for v in (*d.trucks, *d.airplanes) if lm.where(problem, state, v) == y]
            v = s if s not in problem.fixed else [*there, *d.trucks, *d.airplanes][0]
            out.append(Action(f"unload-{d.kind(v)}", (x, v, y)))
        elif kind == "truck" and y in problem.fixed:
            out.append(Action("drive-truck", (x, s, y, d.city[problem.fixed.index(y)])))
        elif kind == "airplane" and y in problem.fixed:
            out.append(Action("fly-airplane", (x, s, y)))
        else:
            raise ProblemError(f"no {lp.PDDL_DOMAIN} action does {move} ({x} is a {kind})")
        state = (*state[:i], y, *state[i + 1 :])
    return tuple(out)


@functools.lru_cache(maxsize=4096)
def _tables(problem: Problem, data: lm.LogisticsData) -> dict[str, Tensor]:
    """One problem's unpadded static tensors: ``kind`` (n, 3) package / truck / airplane,
    ``allow`` (n, Y) static action columns, and the potential's ``base`` (n, Y), ``req``
    (n, Y, 2, K) (legs needing a truck / an airplane at l), ``unload`` (n, n, K)."""
    n, k, ents = problem.n, len(problem.fixed), problem.entities
    (dist, legs), y = lm.routes(data, problem.fixed), n + k
    z = functools.partial(torch.zeros, dtype=torch.float64)
    kind, allow, base, req, unload = z(n, 3), z(n, y), z(n, y), z(n, y, 2, k), z(n, n, k)
    for i, x in enumerate(ents):
        kind[i, ROW[data.kind(x)]] = 1.0
        if data.kind(x) == "package":
            allow[i] = torch.tensor([float(data.kind(v) != "package") for v in ents] + [1.0] * k)
        else:
            allow[i, [n + j for j in lm.reach(problem, x)]] = 1.0

    def route(i: int, col: int, start: int, goal: int) -> None:
        base[i, col] += UNREACHABLE if math.isinf(dist[start][goal]) else 0.0
        for vehicle, origin in legs[start][goal]:
            base[i, col] += 3.0  # load, move, unload
            req[i, col, ROW[vehicle] - 1, origin] += 1.0

    for x, g in ((x, g) for x, g in problem.goal if data.kind(x) == "package"):
        i, gj = ents.index(x), problem.fixed.index(g)
        for j in range(k):
            route(i, n + j, j, gj)
        for v, vehicle in ((v, e) for v, e in enumerate(ents) if data.kind(e) != "package"):
            u = min(lm.reach(problem, vehicle), key=lambda u: (dist[u][gj], u != gj))
            base[i, v], unload[i, v, u] = 1.0, 1.0
            route(i, v, u, gj)
    return {"kind": kind, "allow": allow, "base": base, "req": req, "unload": unload}


def encode(
    problems: Sequence[Problem], states: Sequence[State], dtype: torch.dtype = torch.float32
) -> SoftBatch:
    """`encode_supports`, static action mask; ``static``: `_tables` padded, req (B, N, Y, 2K)."""
    batch = encode_supports(problems, states, dtype)
    b, n, y = batch.F0.shape
    shapes = {"kind": (3,), "allow": (y,), "base": (y,), "req": (y, 2, y - n), "unload": (n, y - n)}
    s = {key: torch.zeros(b, n, *shape, dtype=dtype) for key, shape in shapes.items()}
    for i, p in enumerate(problems):
        t, pn, pk = {k: v.to(dtype) for k, v in _tables(p, p.data).items()}, p.n, len(p.fixed)
        cols = torch.cat([torch.arange(pn), n + torch.arange(pk)])  # unpadded -> padded column
        s["kind"][i, :pn] = t["kind"]
        s["allow"][i, :pn, cols], s["base"][i, :pn, cols] = t["allow"], t["base"]
        s["req"][i, :pn, cols, :, :pk], s["unload"][i, :pn, :pn, :pk] = t["req"], t["unload"]
    allow = batch.action_mask[..., :-1] & (s.pop("allow") > 0)  # (B, N, Y)
    mask = torch.cat([allow, batch.action_mask[..., -1:]], -1)  # (B, N, A)
    s["req"] = s["req"].flatten(-2)  # (B, N, Y, 2K)
    return SoftBatch(batch.F0, batch.entity_mask, mask, batch.goal, s)


def soft_legality(F: Tensor, batch: SoftBatch) -> Tensor:
    """Soft legality of every move by product t-norms, (B, N, Y) -> (B, N, Y), times the static
    mask: load(p -> v) = sum_l F[p, l] F[v, l]; unload(p -> l) = sum_v F[p, v] F[v, l];
    drive/fly(v -> l) = 1 - F[v, l]."""
    n = batch.n
    loc = F[..., n:]  # (B, N, K)
    together = loc @ loc.transpose(-1, -2)  # (B, N, N): at the same location
    carried = F[..., :n] @ loc  # (B, N, K): in a vehicle at l
    package = batch.static["kind"][..., :1]  # (B, N, 1)
    to_loc = package * carried + (1.0 - package) * (1.0 - loc)  # (B, N, K)
    return torch.cat([together, to_loc], dim=-1) * batch.action_mask[..., :-1].to(F.dtype)


def step(F: Tensor, M: Tensor, batch: SoftBatch) -> tuple[Tensor, Tensor]:
    """One soft transition with priority competition (the departure in the module docstring):
    g~ = M legal; rho(x) = sum_y g~(x, y); q(x) = prod_{x' < x} (1 - rho(x')); g = g~ q;
    F' = (1 - m) F + g, m(x) = sum_y g(x, y). F (B, N, Y), M (B, N, A) -> (F', g)."""
    g_raw = M[..., :-1] * soft_legality(F, batch)  # (B, N, Y)
    free = 1.0 - g_raw.sum(-1)  # (B, N)
    q = torch.cat([torch.ones_like(free[:, :1]), free[:, :-1]], dim=-1).cumprod(-1)  # (B, N)
    g = g_raw * q.unsqueeze(-1)  # (B, N, Y)
    return (1.0 - g.sum(-1, keepdim=True)) * F + g, g


def consistency(F: Tensor, batch: SoftBatch) -> Tensor:
    """T_P: row normalisation (vehicles have unlimited capacity). (B, N, Y)."""
    return row_normalise(F)


def potential(F: Tensor, batch: SoftBatch) -> Tensor:
    """Expected remaining actions (module docstring), (B, N, Y) -> (B,):
    sum_{p, y} F[p, y] (base[p, y] + sum_{kind, l} req[p, y, kind, l] absent_kind(l)),
    absent_kind(l) = prod_{v of kind} (1 - F[v, l]),
    + sum_{p, v} F[p, v] sum_l unload[p, v, l] (1 - F[v, l]) + sum_{goal v} (1 - F[v, g(v)])."""
    s, n = batch.static, batch.n
    loc = F[..., n:]  # (B, N, K)
    vehicles = s["kind"][..., 1:].transpose(1, 2).unsqueeze(-1)  # (B, 2, N, 1)
    absent = (1.0 - vehicles * loc.unsqueeze(1)).prod(2).flatten(1)  # (B, 2K): none of a kind
    cost = s["base"] + torch.einsum("bnyj,bj->bny", s["req"], absent)  # (B, N, Y)
    away = s["unload"].sum(-1) - torch.einsum("bpvk,bvk->bpv", s["unload"], loc)  # (B, N, N)
    vehicle_goals = (1.0 - s["kind"][..., 0]) * (batch.goal * (1.0 - F)).sum(-1)  # (B, N)
    return (F * cost).sum((1, 2)) + (F[..., :n] * away).sum((1, 2)) + vehicle_goals.sum(-1)


def goal_loss(F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
    """``potential`` (default) or ``atoms`` (the paper's CE on the goal atoms). -> (B,)."""
    if kind == "atoms":
        return goal_cross_entropy(F, batch.goal)
    if kind in ("potential", "default"):
        return potential(F, batch)
    raise ProblemError(f"unknown goal loss {one_of(kind, GOAL_LOSSES)}")


# ------------------------------------------------------------------------------- samples


def random_problem(cities: int, locations: int, packages: int, planes: int, seed: int) -> Problem:
    """A random problem: one truck per city, ``locations`` per city (the first an airport),
    airplanes at random airports, packages and their goals at random locations (at least one
    package away from its goal)."""
    rng = random.Random(seed)
    cs = [f"c{i}" for i in range(cities)]
    city = {f"l{i}-{j}": c for i, c in enumerate(cs) for j in range(locations)}
    locs, ports = list(city), [f"l{i}-0" for i in range(cities)]
    support = {f"t{i}": f"l{i}-{rng.randrange(locations)}" for i in range(cities)}
    support |= {f"a{i}": rng.choice(ports) for i in range(planes)}
    support |= {f"p{i}": rng.choice(locs) for i in range(packages)}
    goal = [(f"p{i}", rng.choice(locs)) for i in range(packages)]
    if all(support[p] == g for p, g in goal):
        goal[0] = ("p0", rng.choice([x for x in locs if x != support["p0"]]))
    kinds = {c: "city" for c in cs} | {x: "location" for x in locs}
    kinds |= {x: {"t": "truck", "a": "airplane", "p": "package"}[x[0]] for x in support}
    order = [*(f"a{i}" for i in range(planes)), *cs, *(f"t{i}" for i in range(cities)), *locs]
    order += [f"p{i}" for i in range(packages)]
    name = f"logistics-c{cities}-s{locations}-p{packages}-a{planes}-{seed}"
    return lp.make_problem(name, kinds, city, ports, support, goal, order)


SIZES = ((2, 1, 1, 1), (2, 2, 2, 1), (3, 1, 2, 2), (3, 2, 3, 2))  # cities, locations, ...


def samples(seed: int):
    """Random problems of 2-3 cities, 1-2 locations per city, 1-3 packages, 1-2 airplanes."""
    for cities, locations, packages, planes in SIZES:
        yield random_problem(cities, locations, packages, planes, seed)


class Logistics(DomainBase):
    """The logistics domain object the shared planner drives (see task.domains.base.Domain)."""

    name, size_name, goal_losses, distributions = lp.NAME, "packages", GOAL_LOSSES, True
    encode = staticmethod(encode)
    soft_legality = staticmethod(soft_legality)
    step = staticmethod(step)
    decode = staticmethod(relational_decode)
    consistency = staticmethod(consistency)
    cycle_loss = staticmethod(zero_cycle_loss)
    goal_loss = staticmethod(goal_loss)
    initial_state = staticmethod(initial_state)
    check_move = staticmethod(check_move)
    apply_move = staticmethod(apply_move)
    is_goal = staticmethod(is_goal)
    lower_bound = staticmethod(lower_bound)
    legal_moves = staticmethod(legal_moves)
    to_actions = staticmethod(user_actions(to_actions))  # the user's names
    to_atoms = staticmethod(user_atoms(lp.to_atoms))
    to_pddl = staticmethod(lp.to_pddl)
    from_pddl = staticmethod(lp.from_pddl)
    matches = staticmethod(lp.matches)
    pddl_domain_text = staticmethod(lp.pddl_domain_text)
    samples = staticmethod(samples)

    @staticmethod
    def shape_key(problem: Problem) -> tuple[int, int]:
        return (problem.n, len(problem.fixed))

    @staticmethod
    def size(problem: Problem) -> int:
        return len(problem.data.packages)


DOMAIN = Logistics()
