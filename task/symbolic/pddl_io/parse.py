"""Domains and problems parsed through the `pddl` library: one `PDDLError` line per failure.

Every failure names the file (or the ``source`` given for text): a missing file, a parse error
(condensed to line and column), a problem whose ``:domain`` does not match the domain, an atom
that names an unknown predicate or object (`task.symbolic.pddl_io.names`). Text as other tools
write it is read as they mean it (`task.symbolic.pddl_io.style`).

The `pddl` library compiles its grammar on every ``pddl.parse_*`` call (about 60 ms); here the
compiled grammar is built once per process for both start symbols (`_grammar`, in memory: the
library writes nothing outside the files it is told to), and a fresh transformer is used per
file, so the library's per-parser state never leaks from one file into the next.
"""

from __future__ import annotations

import functools
import re
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
from task.symbolic.pddl_io.names import check_names
from task.symbolic.pddl_io.style import domain_style, problem_style
from task.symbolic.pddl_io.text import one_line, read_text

_MAX_EXPECTED = 8


_STARTS = ("domain", "problem")


@functools.cache
def _grammar() -> lark.Lark:
    """The compiled (immutable) LALR grammar of the `pddl` library, one parser for both start
    symbols (`_STARTS`), built on first use (about 0.12 s) and kept for the process: a pure
    memo of a value that depends on nothing but the installed grammar. Nothing is written to
    disk (a table cache under the user's home saved about 0.1 s of a command's start)."""
    return lark.Lark(
        GRAMMAR_FILE.read_text(),
        parser="lalr",
        import_paths=[PARSERS_DIRECTORY],
        start=list(_STARTS),
    )


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
        tree = _grammar().parse(text, start=start)
        return transformer.transform(tree)
    except lark.exceptions.UnexpectedInput as exc:
        raise _syntax_error(source, exc) from None
    except lark.exceptions.VisitError as exc:
        inner = exc.orig_exc
        raise PDDLError(
            f"{source}: invalid {start}: {one_line(inner) or type(inner).__name__}"
        ) from None
    except (LibraryPDDLError, lark.exceptions.LarkError) as exc:
        raise PDDLError(f"{source}: invalid {start}: {one_line(exc)}") from None


def parse_domain(text: str, source: str = "<domain>") -> Domain:
    """Parse domain PDDL text; ``source`` names it in error messages. Text as other tools
    write it is read as they mean it (`domain_style`: any case, empty sections, undeclared
    requirements)."""
    return _parse(domain_style(text), "domain", DomainTransformer(), source)


def parse_problem(
    text: str, source: str = "<problem>", domain: Domain | None = None
) -> PDDLProblem:
    """Parse problem PDDL text; if ``domain`` is given, its name must match ``:domain``."""
    problem = _parse(problem_style(text), "problem", ProblemTransformer(), source)
    if domain is not None and str(problem.domain_name).lower() != str(domain.name).lower():
        raise PDDLError(
            f"{source}: problem {problem.name} is for domain {str(problem.domain_name)!r}, "
            f"not {str(domain.name)!r}"
        )
    if domain is not None:
        check_names(problem, domain, object_order(text), source)
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


def problem_with(from_pddl, domain, text: str, source: str = "<problem>"):
    """Problem PDDL ``text`` parsed against ``domain`` and turned into a `Problem` by a domain
    file's ``from_pddl(domain, parsed, order)`` (the file's object order kept); a PDDLError
    of either step names ``source``."""
    parsed = parse_problem(text, source, domain)
    try:
        return from_pddl(domain, parsed, object_order(text))
    except PDDLError as exc:
        raise PDDLError(f"{source}: {exc}") from None
