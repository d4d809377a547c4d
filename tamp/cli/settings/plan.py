"""``tamp plan`` and ``tamp example`` at the edge: the parsed options turned once into the typed
settings the commands run with (`PlanSettings`), and the recorded configuration built from them.

`plan_settings` and `example_settings` are the only functions of these commands that read the
argparse namespace (refusing ``--scene`` / ``--placements`` where they do nothing, one line,
exit 2); below them (`tamp.cli.plan`) the commands take `PlanSettings` only, and `plan_record`
is the ``config`` their ``--json`` reports record. Parsing-level only: nothing here plans.
"""

from __future__ import annotations

import argparse
from dataclasses import asdict, dataclass

from tamp.cli.options import PlannerOverrides, check_workcell, planner_overrides


@dataclass(frozen=True)
class Workcell:
    """``tamp plan``'s table: ``scene`` (a named workcell, planned on with ``--motion-aware``),
    ``placements`` (how far off a slot's centre a block may be placed, m) and ``rules`` (the
    ``--domain-rules`` to plan with; None: recognised from the PDDL domain)."""

    scene: str = "tabletop"
    placements: float = 0.0
    rules: str | None = None


@dataclass(frozen=True)
class PlanSettings:
    """What ``plan`` and ``example`` run with: the planner options given (`PlannerOverrides`,
    laid over the planned domain's defaults once the PDDL is read), the ``seed``, torch
    ``threads``, the PDDL files (``domain``, ``problem``; None: the embedded example), the
    ``workcell`` (``plan`` only; None for ``example``), ``out`` (the plan file or the example's
    folder) and ``json``."""

    planner: PlannerOverrides
    seed: int
    threads: int
    domain: str | None = None
    problem: str | None = None
    workcell: Workcell | None = None
    out: str | None = None
    json: bool = False


def plan_settings(args: argparse.Namespace) -> PlanSettings:
    """``plan DOMAIN PROBLEM``: the options as `PlanSettings` (``--scene`` and ``--placements``
    refused where they take no effect, `tamp.cli.options.check_workcell`)."""
    check_workcell(args, executes=False)
    workcell = Workcell(args.scene, args.placements, args.domain_rules)
    return PlanSettings(
        planner_overrides(args),
        args.seed,
        args.threads,
        domain=args.domain,
        problem=args.problem,
        workcell=workcell,
        out=args.out,
        json=args.json,
    )


def example_settings(args: argparse.Namespace) -> PlanSettings:
    """``example``: the options as `PlanSettings` (the embedded example, no workcell)."""
    return PlanSettings(
        planner_overrides(args), args.seed, args.threads, out=args.out, json=args.json
    )


def plan_record(settings: PlanSettings, domain: str | None = None) -> dict:
    """The recorded configuration of ``plan`` and ``example``: the planner config (with
    ``domain``'s defaults; None: the generic defaults), seed, threads, and for ``plan`` the
    table planned on and the rules."""
    body = {
        **asdict(settings.planner.config(domain)),
        "seed": settings.seed,
        "threads": settings.threads,
    }
    if settings.workcell is not None:
        body |= {"scene": settings.workcell.scene, "placements": settings.workcell.placements}
        body["domain_rules"] = settings.workcell.rules
    return body


@dataclass(frozen=True)
class ValidateSettings:
    """What ``validate`` reads: the PDDL ``domain`` and ``problem`` files and the ``plan`` file
    (as typed), and ``json``."""

    domain: str
    problem: str
    plan: str
    json: bool = False


def validate_settings(args: argparse.Namespace) -> ValidateSettings:
    """``validate DOMAIN PROBLEM PLAN``: the options as `ValidateSettings`."""
    return ValidateSettings(args.domain, args.problem, args.plan, args.json)


def validate_record(settings: ValidateSettings) -> dict:
    """The recorded configuration of ``validate``: its inputs only."""
    return {"domain": settings.domain, "problem": settings.problem, "plan": settings.plan}
