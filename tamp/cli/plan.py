"""What the ``tamp`` subcommands do: plan, validate, example. Each returns the exit code.

0: success (a valid plan); 1: no plan or an invalid plan (an empty plan file that does not reach
the goal included, as in ``tamp run --plan``). Bad input raises `TampError`, which
`tamp.cli.main` turns into one ``tamp: error:`` line and exit code 2.

``tamp plan`` tells an unsolvable problem from a planner out of budget
(`task.symbolic.proofs`): the cheap proofs run before planning, exhaustive search after the
planner found no plan; the output is ``unsolvable: REASON`` or ``no plan found within
BUDGET``, both exit code 1. A plan is printed (and written to ``--out``) only when it
validates against the PDDL.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import replace
from pathlib import Path

from pddl.core import Domain

from tamp.cli import report
from tamp.cli.recorded import out_file, out_folder
from tamp.cli.settings.plan import PlanSettings, ValidateSettings, plan_record
from task import data
from task.config import PlannerConfig
from task.deadline import NO_DEADLINE, Deadline, TimeLimitReached
from task.domains import blocksworld, get_domain
from task.errors import TampError
from task.instances import Instance, example, from_files
from task.planner import plan
from task.problem import Move, PlanResult, PlanStatus
from task.symbolic import pddl_io, strips
from task.symbolic.proofs import Proof, prove_unsolvable
from task.symbolic.search import optimal_moves
from task.symbolic.validate import Validation, validate, validate_files

PROOF_FIRST_S = 3.0  # seconds h^2 before planning may take (grounding: only --time-limit bounds it)
PROOF_AFTER_S = 10.0  # seconds the proofs after a failed plan may take (h^2, exhaustive search)


def _write(path: Path, text: str) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise TampError(f"cannot write {path} ({exc.strerror or exc})") from None


def _solve(
    domain: Domain, instance: Instance, settings: PlanSettings, deadline: Deadline = NO_DEADLINE
):
    """Plan ``instance`` and validate its PDDL plan against its PDDL (None without a plan);
    ``(recorded config, config, result, actions, validation)``. ``deadline``: the command's,
    which the planner stops at too."""
    from tamp.sweep import torch_threads

    recorded = plan_record(settings, instance.problem.domain)
    config = settings.planner.config(instance.problem.domain)
    with torch_threads(settings.threads):
        if settings.planner.get("lambda_motion"):
            result = _plan_on_table(instance.problem, config, settings)
        else:
            result = plan(instance.problem, config, settings.seed, deadline=deadline)
    actions: tuple = ()
    validation = None
    if result.solved:
        actions = get_domain(instance.problem.domain).to_actions(
            instance.problem, result.plan.moves, strict=False
        )  # an illegal move too: the validator names it, and the plan is not printed
        validation = validate(domain, instance.pddl, actions)
    return recorded, config, result, actions, validation


def _plan_on_table(problem, config: PlannerConfig, settings: PlanSettings) -> PlanResult:
    """``--motion-aware``: plan with the arm's move costs, the problem laid out on ``--scene``
    (seeded by ``--seed``), the arm at home, on the scene's table slots (`tamp.slots`): a
    move onto the table carries the place it goes to."""
    if problem.domain != "blocksworld":
        raise TampError(
            f"--motion-aware prices arm moves of blocksworld problems on a table; "
            f"this is a {problem.domain} problem"
        )
    from motion.ik import IKSolver
    from robots.panda import PANDA
    from tamp.arm.arm import Arm
    from tamp.obstacles import with_scene
    from tamp.scene import SceneConfig, layout
    from tamp.slots import plan_on_places

    workcell, seed = settings.workcell, settings.seed
    scene = with_scene(SceneConfig(), workcell.scene)
    poses = layout(problem.entities, problem.init, scene, seed)
    arm = Arm(IKSolver(), PANDA.q_home)
    found = plan_on_places(problem, poses, scene, arm, config, seed, reach=workcell.placements)
    return replace(found, problem=problem)


def _plan_json(
    config: dict,
    result: PlanResult,
    actions: tuple,
    validation: Validation | None,
    seed: int,
    proof: Proof | None = None,
    note: str = "",
) -> str:
    """The ``--json`` report; ``status`` is "unsolvable" when ``proof`` proves it, and
    ``proof`` says what was tried when the planner found no plan; ``note``: why a domain that
    nearly matches a hand-written one is planned by the generic lift ("" otherwise)."""
    unsolvable = proof is not None and proof.unsolvable
    return json.dumps(
        {
            "problem": result.problem.name,
            "status": "unsolvable" if unsolvable else result.status.value,
            "valid": validation is not None and validation.valid,
            "proof": None if proof is None else {"reason": proof.reason, "method": proof.method},
            "domain_rules": result.problem.domain,
            "note": note,
            "moves": [_move_json(m) for m in result.plan.moves],
            "actions": [str(a).lower() for a in actions],
            "validation": None if validation is None else report.validation_dict(validation),
            "stats": result.stats,
            "seed": seed,
            "config": config,
        },
        indent=2,
    )


def _move_json(move: object) -> object:
    """A relational move as ``[entity, target]`` (``[entity, "table", [x, y]]`` when it names
    its table place); any other move (a ground action) as text."""
    if not isinstance(move, Move):
        return str(move).lower()
    at = getattr(move, "at", None)
    return [move.entity, move.target] + ([[round(v, 4) for v in at]] if at is not None else [])


def _places(result: PlanResult) -> str:
    """One line naming where each move onto the table puts its block ("" when none does)."""
    placed = [m for m in result.plan.moves if getattr(m, "at", None) is not None]
    if not placed:
        return ""
    where = ", ".join(f"{m.entity} at ({m.at[0]:.2f}, {m.at[1]:.2f})" for m in placed)
    return f"table places (m, base frame): {where}\n"


def _outcome(
    result: PlanResult,
    validation: Validation | None,
    instance: Instance,
    config: PlannerConfig,
) -> str:
    """The validation line of a plan, else ``no plan found within BUDGET`` (`_budget`)."""
    windows, moves = result.stats.get("windows", 0), len(result.plan)
    took = (
        f"{moves} move{'' if moves == 1 else 's'}, {windows} window{'' if windows == 1 else 's'}, "
        f"{result.stats['time_s']:.2f} s"
    )
    if validation is None:
        left = " ".join(strips.atom_str(a) for a in _unmet(result, instance))
        if "time_limit" in result.stats:
            return (
                f"no plan found within the time limit: {result.stats['time_limit']}; unmet: {left}"
            )
        budget = _budget(result, config)
        return f"no plan found within {budget}: goal not reached after {took}; unmet: {left}"
    return f"{report.validation_line(validation)} ({took})"


def _budget(result: PlanResult, config: PlannerConfig) -> str:
    """What the planner was allowed: its windows, and the fallback search's expansions when
    that ran."""
    windows = f"{config.max_windows} window{'' if config.max_windows == 1 else 's'}"
    if "fallback" not in result.stats:
        return windows
    return f"{windows} and {config.fallback_nodes} fallback search expansions"


def _unmet(result: PlanResult, instance: Instance) -> list[tuple[str, ...]]:
    """The PDDL goal atoms that do not hold after the plan's legal moves."""
    domain = get_domain(result.problem.domain)
    state = domain.initial_state(result.problem)
    for move in result.plan.moves:
        if domain.check_move(result.problem, state, move) is not None:
            break
        state = domain.apply_move(result.problem, state, move)
    holds = domain.to_atoms(result.problem, state)
    return [a for a in strips.goal_atoms(instance.pddl) if a not in holds]


def _proved_first(settings: PlanSettings, deadline: Deadline = NO_DEADLINE) -> tuple[str, Proof]:
    """The problem's name and the cheap proofs (`prove_unsolvable` without search) on the
    PDDL files, after they parse and stay within the STRIPS the planners plan (else
    `TampError`, exit code 2)."""
    domain_text = pddl_io.read_text(settings.domain)
    domain = pddl_io.parse_domain(domain_text, str(settings.domain))
    pddl_io.check_strips(domain_text, str(settings.domain))
    problem_text = pddl_io.read_text(settings.problem)
    problem = pddl_io.parse_problem(problem_text, str(settings.problem), domain)
    pddl_io.check_strips(problem_text, str(settings.problem))
    proof = prove_unsolvable(domain, problem, time_limit_s=PROOF_FIRST_S, deadline=deadline)
    return str(problem.name), proof


def _proved_after(domain: Domain, instance: Instance, deadline: Deadline = NO_DEADLINE) -> Proof:
    """Exhaustive search too, once the planner found no plan (`PROOF_AFTER_S` at most, and
    never past the command's ``deadline``)."""
    return prove_unsolvable(
        domain, instance.pddl, exhaustive=True, time_limit_s=PROOF_AFTER_S, deadline=deadline
    )


def _proof_json(name: str, proof: Proof, seed: int) -> str:
    """The ``--json`` report of a problem proved unsolvable before planning."""
    return json.dumps(
        {
            "problem": name,
            "status": "unsolvable",
            "valid": False,
            "reason": proof.reason,
            "method": proof.method,
            "actions": [],
            "seed": seed,
        },
        indent=2,
    )


def _stopped(settings: PlanSettings, name: str, proof: Proof, why: str, wall: float) -> int:
    """The report of a ``tamp plan`` whose time limit passed before planning began (``why``:
    the phase that stopped, `TimeLimitReached`'s message); exit code 1."""
    limit = settings.planner.get("time_limit_s")
    said = f"stopped at the {limit:g} s time limit before planning ({why})"
    if not settings.json:
        print(f"no plan found within the time limit: {said}")
        return 1
    body = {
        "problem": name,
        "status": PlanStatus.NO_PLAN.value,
        "valid": False,
        "proof": {"reason": proof.reason, "method": proof.method},
        "domain_rules": None,
        "note": "",
        "moves": [],
        "actions": [],
        "validation": None,
        "stats": {"time_s": wall, "time_limit": said},
        "seed": settings.seed,
        "config": plan_record(settings),
    }
    print(json.dumps(body, indent=2))
    return 1


def plan_command(settings: PlanSettings) -> int:
    """``tamp plan DOMAIN PROBLEM``: the PDDL plan and its validation line; ``unsolvable:
    REASON`` when a proof says no plan exists, ``no plan found within BUDGET`` otherwise."""
    out_file(settings.out)
    start = time.perf_counter()  # the reported time: the whole command's work, wall clock
    deadline = Deadline.after(settings.planner.get("time_limit_s"), start)
    name, proof = _proved_first(settings, deadline)
    if proof.unsolvable:
        if settings.json:
            print(_proof_json(name, proof, settings.seed))
        else:
            print(f"unsolvable: {proof.reason}")
        return 1
    rules = settings.workcell.rules
    try:
        domain, instance = from_files(settings.domain, settings.problem, rules, deadline)
    except TimeLimitReached as exc:  # the lift grounds the problem again, for the planner
        return _stopped(settings, name, proof, str(exc), time.perf_counter() - start)
    if instance.note and not settings.json:  # a near miss of a hand-written domain: the lift plans
        print(f"note: {instance.note}", file=sys.stderr)
    recorded, config, result, actions, validation = _solve(domain, instance, settings, deadline)
    valid = validation is not None and validation.valid
    said = result.stats.get("reason") if result.status is PlanStatus.UNSOLVABLE else None
    searched = validation is not None or said is not None  # no proof needed after either
    after = None if searched else _proved_after(domain, instance, deadline)
    wall = time.perf_counter() - start
    stats = {**result.stats, "plan_time_s": result.stats.get("time_s"), "time_s": wall}
    result = replace(result, stats=stats)
    if settings.out is not None and valid:
        _write(Path(settings.out), pddl_io.format_plan(actions))
    if settings.json:
        print(
            _plan_json(recorded, result, actions, validation, settings.seed, after, instance.note)
        )
    elif after is not None and after.unsolvable:
        print(f"unsolvable: {after.reason}")
    elif said is not None:  # the planner's own reason (a goal the scene cannot hold)
        print(f"unsolvable: {said}")
    else:
        if valid:
            print(pddl_io.format_plan(actions), end="")
            print(_places(result), end="")
        print(_outcome(result, validation, instance, config))
        if after is not None:
            print(f"({after.reason})")
    return 0 if valid else 1


def validate_command(settings: ValidateSettings) -> int:
    """``tamp validate DOMAIN PROBLEM PLAN``: VALID or the first failing step."""
    validation = validate_files(settings.domain, settings.problem, settings.plan)
    if settings.json:
        print(json.dumps(report.validation_dict(validation), indent=2))
    else:
        print(report.validation_line(validation))
    return 0 if validation.valid else 1


def example_command(settings: PlanSettings) -> int:
    """``tamp example``: plan the embedded 5-block example and show every stage (no robot;
    ``tamp demo`` runs it with the arm)."""
    out_folder(settings.out)
    domain, instance = example()
    recorded, config, result, actions, validation = _solve(domain, instance, settings)
    written = []
    if settings.out is not None:
        out = Path(settings.out)
        for name in (data.DOMAIN_FILE, data.EXAMPLE_FILE):
            _write(out / name, data.read_text(name))
            written.append(name)
        if validation is not None and validation.valid:
            _write(out / "example-5.plan", pddl_io.format_plan(actions))
            written.append("example-5.plan")
    if settings.json:
        print(_plan_json(recorded, result, actions, validation, settings.seed))
        return 0 if validation is not None and validation.valid else 1
    problem = instance.problem
    best = optimal_moves(problem)
    lines = [
        f"soft-tamp example: {data.source(data.EXAMPLE_FILE)}, {problem.n} blocks, "
        f"optimal plan {'?' if best is None else len(best)} moves (A*)",
        "",
        *report.problem_picture(problem),
        "",
        f"soft-T_P planner (T={config.horizon}, {config.restarts} restarts, seed {settings.seed}):",
        *(f"  {k}. {m}" for k, m in enumerate(result.plan.moves, start=1)),
        "",
        f"PDDL plan ({blocksworld.PDDL_DOMAIN}):",
        pddl_io.format_plan(actions).rstrip() if validation and validation.valid else "(none)",
        "",
        _outcome(result, validation, instance, config),
    ]
    print("\n".join(lines))
    if written:
        print(f"wrote {', '.join(written)} to {settings.out}")
    return 0 if validation is not None and validation.valid else 1
