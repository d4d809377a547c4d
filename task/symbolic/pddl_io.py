"""PDDL in and out: domains and problems through the `pddl` library, plans in the VAL format.

Every failure is one `PDDLError` line that names the file (or the ``source`` given for text):
a missing file, a parse error (condensed to line and column), a problem whose ``:domain`` does
not match the domain. Plans are written in the PlanBench / VAL / Fast Downward format: one
``(name arg1 arg2)`` per line, then a ``; cost = N (unit cost)`` trailer. `parse_plan_lines` is
the one plan reader of the project (``tamp validate`` and ``tamp run --plan`` both use it): that
format with ``;`` comments, optional step numbers (``0: (pick-up a)``, LPG and LLM plans) and
``[duration]`` suffixes, or relational moves (``move(a -> b)``, the form `task.problem.Move`
prints, or ``move(a, b)`` or ``a -> b``), one kind per plan.

The `pddl` library compiles its grammar on every ``pddl.parse_*`` call (about 60 ms); here the
compiled grammar is built once per start symbol and a fresh transformer is used per file, so
the library's per-parser state never leaks from one file into the next.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import lark
from pddl.core import Domain
from pddl.core import Problem as PDDLProblem
from pddl.exceptions import PDDLError as LibraryPDDLError
from pddl.parser import GRAMMAR_FILE, PARSERS_DIRECTORY
from pddl.parser.domain import DomainTransformer
from pddl.parser.problem import ProblemTransformer

from task.errors import PDDLError
from task.problem import Action, Move

_NUMBER = re.compile(r"^\d+\s*[:.]\s*")  # "0: (pick-up a)" (LPG, LLM plans)
_ACTION = re.compile(r"^\(\s*([^\s()]+)((?:\s+[^\s()]+)*)\s*\)(?:\s*\[[^\]]*\])?$")
_MOVE = re.compile(r"^move\s*\(\s*([^\s(),]+?)\s*(?:->|,)\s*([^\s(),]+)\s*\)$", re.IGNORECASE)
_ARROW = re.compile(r"^([^\s(),]+?)\s*->\s*([^\s(),]+)$")
_MAX_EXPECTED = 8


@functools.cache
def _grammar(start: str) -> lark.Lark:
    """The compiled (immutable) LALR grammar of the `pddl` library for ``start``."""
    return lark.Lark(
        GRAMMAR_FILE.read_text(),
        parser="lalr",
        import_paths=[PARSERS_DIRECTORY],
        start=start,
    )


def read_text(path: str | Path) -> str:
    """The text of ``path``; PDDLError naming the file if it is missing, unreadable or not
    UTF-8 text (a binary file given by mistake: an image, a checkpoint, an archive)."""
    try:
        return Path(path).read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise PDDLError(f"{path}: no such file") from None
    except UnicodeDecodeError as exc:
        raise PDDLError(
            f"{path}: not a text file (byte {exc.start} is not UTF-8); expected PDDL or plan text"
        ) from None
    except OSError as exc:
        raise PDDLError(f"{path}: cannot read ({exc.strerror or exc})") from None


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _syntax_error(source: str, exc: lark.exceptions.UnexpectedInput) -> PDDLError:
    """Condense a lark error to ``source: parse error at line L, column C: ...``."""
    where = f"line {exc.line}, column {exc.column}" if exc.line > 0 else "end of file"
    if isinstance(exc, lark.exceptions.UnexpectedCharacters):
        what = f"unexpected character {exc.char!r}"
    elif isinstance(exc, lark.exceptions.UnexpectedToken):
        what = f"unexpected {exc.token.value!r}" if exc.token.value else "unexpected end of file"
    else:
        what = "unexpected end of file"
    expected = sorted(getattr(exc, "expected", None) or getattr(exc, "allowed", None) or ())
    if expected:
        more = ", ..." if len(expected) > _MAX_EXPECTED else ""
        what += f" (expected one of: {', '.join(expected[:_MAX_EXPECTED])}{more})"
    return PDDLError(f"{source}: parse error at {where}: {what}")


def _parse(text: str, start: str, transformer: lark.Transformer, source: str) -> Any:
    try:
        tree = _grammar(start).parse(text)
        return transformer.transform(tree)
    except lark.exceptions.UnexpectedInput as exc:
        raise _syntax_error(source, exc) from None
    except lark.exceptions.VisitError as exc:
        inner = exc.orig_exc
        raise PDDLError(
            f"{source}: invalid {start}: {_one_line(inner) or type(inner).__name__}"
        ) from None
    except (LibraryPDDLError, lark.exceptions.LarkError) as exc:
        raise PDDLError(f"{source}: invalid {start}: {_one_line(exc)}") from None


_TYPES = re.compile(r"\(\s*:types\b", re.IGNORECASE)
_REQUIREMENTS = re.compile(r"\(\s*:requirements\b", re.IGNORECASE)


def _implied_typing(text: str) -> str:
    """Domain text with ``:typing`` added to its requirements when it declares ``(:types``
    without it: many IPC domains (miconic, say) do, and Fast Downward and VAL accept them."""
    body = re.sub(r";[^\n]*", " ", text)
    if not _TYPES.search(body) or re.search(r":typing\b", body, re.IGNORECASE):
        return text
    if _REQUIREMENTS.search(text):
        return _REQUIREMENTS.sub(lambda m: m.group(0) + " :typing", text, count=1)
    return re.sub(
        r"(\(\s*domain\s+[^\s()]+\s*\))",
        lambda m: m.group(1) + " (:requirements :typing)",
        text,
        count=1,
        flags=re.IGNORECASE,
    )


def parse_domain(text: str, source: str = "<domain>") -> Domain:
    """Parse domain PDDL text; ``source`` names it in error messages. A domain that declares
    types without the ``:typing`` requirement is read as if it had it (`_implied_typing`)."""
    return _parse(_implied_typing(text), "domain", DomainTransformer(), source)


def parse_problem(
    text: str, source: str = "<problem>", domain: Domain | None = None
) -> PDDLProblem:
    """Parse problem PDDL text; if ``domain`` is given, its name must match ``:domain``."""
    problem = _parse(text, "problem", ProblemTransformer(), source)
    if domain is not None and str(problem.domain_name).lower() != str(domain.name).lower():
        raise PDDLError(
            f"{source}: problem {problem.name} is for domain {str(problem.domain_name)!r}, "
            f"not {str(domain.name)!r}"
        )
    return problem


def load_domain(path: str | Path) -> Domain:
    """Read and parse a domain file."""
    return parse_domain(read_text(path), str(path))


def load_problem(path: str | Path, domain: Domain | None = None) -> PDDLProblem:
    """Read and parse a problem file; if ``domain`` is given, its name must match."""
    return parse_problem(read_text(path), str(path), domain)


def object_order(text: str) -> tuple[str, ...]:
    """Object names of problem text in file order, lowercased (``pddl`` keeps only a set).

    Call it on text that `parse_problem` accepted; type annotations (``- type``) are dropped.
    """
    body = re.sub(r";[^\n]*", " ", text)
    match = re.search(r"\(\s*:objects\b([^()]*)\)", body, flags=re.IGNORECASE)
    if match is None:
        return ()
    tokens = match.group(1).split()
    names = [t for i, t in enumerate(tokens) if t != "-" and (i == 0 or tokens[i - 1] != "-")]
    return tuple(dict.fromkeys(n.lower() for n in names))


def load_object_order(path: str | Path) -> tuple[str, ...]:
    """`object_order` of a problem file."""
    return object_order(read_text(path))


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
        line = _NUMBER.sub("", raw.split(";", 1)[0].strip()).lower()
        if not line:
            continue
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


def problem_with(from_pddl, domain, text: str, source: str = "<problem>"):
    """Problem PDDL ``text`` parsed against ``domain`` and turned into a `Problem` by a domain
    file's ``from_pddl(domain, parsed, order)`` (the file's object order kept); a PDDLError
    of either step names ``source``."""
    parsed = parse_problem(text, source, domain)
    try:
        return from_pddl(domain, parsed, object_order(text))
    except PDDLError as exc:
        raise PDDLError(f"{source}: {exc}") from None
