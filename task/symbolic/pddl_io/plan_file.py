"""Plan files: the one plan reader of the project, and plan text in the VAL format.

Plans are written in the PlanBench / VAL / Fast Downward format: one ``(name arg1 arg2)`` per
line, then a ``; cost = N (unit cost)`` trailer. `parse_plan_lines` is the one plan reader of
the project (``tamp validate`` and ``tamp run --plan`` both use it): that format with ``;``
comments, optional step numbers (``0: (pick-up a)``, LPG and LLM plans) and ``[duration]``
suffixes, or relational moves (``move(a -> b)``, the form `task.problem.Move` prints, or
``move(a, b)`` or ``a -> b``), one kind per plan. One step per line: a step after the ``;`` of
a step's line (``(unstack c b); (put-down c)``, the one-line form `bench executability` reads)
is refused rather than read as a comment.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from task.errors import PDDLError
from task.problem import Action, Move
from task.symbolic.pddl_io.text import read_text

_NUMBER = re.compile(r"^\d+\s*[:.]\s*")  # "0: (pick-up a)" (LPG, LLM plans)
_ACTION = re.compile(r"^\(\s*([^\s()]+)((?:\s+[^\s()]+)*)\s*\)(?:\s*\[[^\]]*\])?$")
_MOVE = re.compile(r"^move\s*\(\s*([^\s(),]+?)\s*(?:->|,)\s*([^\s(),]+)\s*\)$", re.IGNORECASE)
_ARROW = re.compile(r"^([^\s(),]+?)\s*->\s*([^\s(),]+)$")


@dataclass(frozen=True)
class PlanLine:
    """One entry of a plan file: its 1-based line number and the action or move on it."""

    lineno: int
    step: Action | Move


def parse_plan_lines(text: str, source: str = "<plan>") -> tuple[PlanLine, ...]:
    """Every action or move of plan text with its line number (the format is in the module
    docstring); names are lowercased. PDDLError naming ``source`` and the line for a malformed
    line or a plan that mixes actions and moves. An empty plan is an empty tuple."""
    entries = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line, _, comment = raw.partition(";")
        line = _NUMBER.sub("", line.strip()).lower()
        if not line:
            continue
        if _is_step(comment.partition(";")[0].strip()):
            raise PDDLError(
                f"{source}: line {lineno}: several actions on one line joined by ';' "
                f"({raw.strip()!r}): a plan file holds one action per line, and ';' starts a "
                "comment"
            )
        if m := _ACTION.match(line):
            entries.append(PlanLine(lineno, Action(m.group(1), tuple(m.group(2).split()))))
        elif m := _MOVE.match(line) or _ARROW.match(line):
            entries.append(PlanLine(lineno, Move(m.group(1), m.group(2))))
        else:
            raise PDDLError(
                f"{source}: line {lineno}: malformed plan line {raw.strip()!r} (expected "
                "'(action-name arg ...)' or a move 'move(a -> b)')"
            )
    kinds = [isinstance(e.step, Move) for e in entries]
    if len(set(kinds)) > 1:
        lineno = entries[kinds.index(not kinds[0])].lineno
        raise PDDLError(f"{source}: line {lineno}: the plan mixes 4-op actions and moves")
    return tuple(entries)


def _is_step(text: str) -> bool:
    """Whether comment text reads as a plan step (an action or a move), not a remark."""
    line = _NUMBER.sub("", text)
    return bool(_ACTION.match(line) or _MOVE.match(line))


def parse_plan(text: str, source: str = "<plan>") -> tuple[Action, ...]:
    """The actions of plan text (`parse_plan_lines`); PDDLError naming the line of a move (a
    move stands for actions that depend on the state: `task.symbolic.validate` expands it)."""
    actions = []
    for entry in parse_plan_lines(text, source):
        if isinstance(entry.step, Move):
            raise PDDLError(
                f"{source}: line {entry.lineno}: {entry.step} is a move, not a PDDL action"
            )
        actions.append(entry.step)
    return tuple(actions)


def read_plan_lines(path: str | Path) -> tuple[PlanLine, ...]:
    """Read a plan file (see `parse_plan_lines`)."""
    return parse_plan_lines(read_text(path), str(path))


def read_plan(path: str | Path) -> tuple[Action, ...]:
    """Read a plan file (see `parse_plan`)."""
    return parse_plan(read_text(path), str(path))


def format_plan(actions: Iterable[Action]) -> str:
    """Plan text: one lowercase ``(name args)`` per line, then ``; cost = N (unit cost)``."""
    lines = [str(a).lower() for a in actions]
    return "".join(f"{line}\n" for line in lines) + f"; cost = {len(lines)} (unit cost)\n"


def write_plan(actions: Iterable[Action], path: str | Path) -> Path:
    """Write `format_plan` text to ``path`` (parent folders are created); returns the path."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(format_plan(actions), encoding="utf-8")
    return out
