"""The problem inputs of `tamp.api`: PDDL read by one rule (a `pathlib.Path` is a file, a
``str`` is PDDL text), the embedded Blocksworld domain and example, `PddlTask` (a parsed PDDL
domain and the planner's problem of it), the domain rules that plan a domain, and `as_task`, the
one reader of every problem input the planning and episode functions take."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from tamp.api.args import SOURCE, TEXT, Kind, checked
from task import data
from task.domains import GENERIC, get_domain, names
from task.domains.match import recognise
from task.errors import PDDLError, TampError
from task.instances import Instance, from_text
from task.problem import Action, Move, Problem
from task.symbolic import pddl_io

if TYPE_CHECKING:  # heavy modules load when a function needs them
    from pddl.core import Domain as PDDLDomain

Source = str | Path  # PDDL text (str) or a PDDL file (Path)
PlanSource = str | Path | Sequence[Action | Move]  # plan text, a plan file, or the steps
EXAMPLE = data.read_text(data.EXAMPLE_FILE)  # the embedded 5-block Blocksworld problem (PDDL)
BLOCKSWORLD = data.read_text(data.DOMAIN_FILE)  # the embedded 4-op Blocksworld domain (PDDL)


@dataclass(frozen=True)
class PddlTask:
    """A problem read from PDDL: the parsed PDDL ``domain`` (what plans are validated against)
    and the ``instance`` (the planner's `task.problem.Problem`, its parsed PDDL problem, known
    optimal length in PDDL actions or None)."""

    domain: PDDLDomain
    instance: Instance

    @property
    def problem(self) -> Problem:
        """The planner's problem: entities, their initial supports, the goal atoms."""
        return self.instance.problem

    @property
    def name(self) -> str:
        return self.instance.name


def pddl_text(source: Source, what: str) -> tuple[str, str]:
    """``(text, label for errors)`` of PDDL given as text (str) or a file (Path)."""
    if isinstance(source, Path):
        return pddl_io.read_text(source), str(source)
    if not isinstance(source, str):
        raise TampError(
            f"{what}: expected PDDL text (str) or a file (pathlib.Path), got {source!r}"
        )
    if "(define" not in source.lower():
        raise PDDLError(
            f"{what}: {source[:40]!r} is not PDDL text (no '(define'); pass a file as "
            "pathlib.Path(...)"
        )
    return source, f"<{what}>"


def domain_names() -> tuple[str, ...]:
    """The registered soft domain rules (`task.domains`): hand-written domains and ``strips``,
    the generic lift that plans any STRIPS domain."""
    return names()


@checked(domain=SOURCE)
def domain_rules(domain: Source) -> str:
    """The name of the rules that plan a PDDL domain: a hand-written domain it matches
    (``blocksworld``, ``logistics``, ``sokoban``), else ``strips`` (the generic soft lift).
    A domain outside the supported STRIPS fragment fails when a problem of it is loaded."""
    text, label = pddl_text(domain, "domain")
    return recognise(pddl_io.parse_domain(text, label))


@checked(problem=SOURCE, domain=SOURCE.optional(), rules=TEXT.optional())
def load_problem(
    problem: Source, domain: Source | None = None, rules: str | None = None
) -> PddlTask:
    """Read a PDDL problem (text or file) of ``domain`` (text or file; None: the embedded 4-op
    Blocksworld domain, `BLOCKSWORLD`). ``rules`` forces the domain rules (`domain_names`;
    ``strips`` plans a known domain with the generic lift); by default they are recognised."""
    domain_text, domain_label = pddl_text(BLOCKSWORLD if domain is None else domain, "domain")
    parsed = pddl_io.parse_domain(domain_text, domain_label)
    text, label = pddl_text(problem, "problem")
    return PddlTask(parsed, from_text(parsed, text, label, rules=rules))


PROBLEM = Kind(
    "a PddlTask, a Problem, PDDL text (str) or a PDDL file (pathlib.Path)",
    lambda v: isinstance(v, PddlTask | Problem | str | Path),
)  # the problem argument of every function that plans or runs one


def as_task(problem: PddlTask | Problem | Source, domain: Source | None = None) -> PddlTask:
    """A `PddlTask` of any problem input; a `Problem` goes through its domain's own PDDL."""
    if isinstance(problem, PddlTask):
        return problem
    if isinstance(problem, Problem):
        rules = get_domain(problem.domain)
        if problem.domain == GENERIC:
            domain_text = rules.pddl_domain_text(problem)
        else:
            domain_text = rules.pddl_domain_text()
        return load_problem(rules.to_pddl(problem), domain_text, problem.domain)
    return load_problem(problem, domain)
