"""PDDL in and out: domains and problems through the `pddl` library, plans in the VAL format.

Every failure is one `PDDLError` line that names the file (or the ``source`` given for text):
a missing file, a parse error (condensed to line and column), a problem whose ``:domain`` does
not match the domain. Plans are written in the PlanBench / VAL / Fast Downward format: one
``(name arg1 arg2)`` per line, then a ``; cost = N (unit cost)`` trailer. `parse_plan_lines` is
the one plan reader of the project (``tamp validate`` and ``tamp run --plan`` both use it): that
format with ``;`` comments, optional step numbers (``0: (pick-up a)``, LPG and LLM plans) and
``[duration]`` suffixes, or relational moves (``move(a -> b)``, the form `task.problem.Move`
prints, or ``move(a, b)`` or ``a -> b``), one kind per plan. One step per line: a step after
the ``;`` of a step's line (``(unstack c b); (put-down c)``, the one-line form `bench
executability` reads) is refused rather than read as a comment.

PDDL as other tools write it is read as they mean it before the library's grammar sees it
(`_domain_style`, `_problem_style`): keywords in any case, empty sections (Tarski's writer
leaves ``(:types)``, ``(:constants)``, ``(:functions)`` empty), requirements used but not
declared or declared but unknown here, ``- object`` annotations, header sections out of order,
actions without a precondition; lines and columns are kept for parse errors. `check_strips`
names the line and the feature of the first construct the planners cannot plan.

The `pddl` library compiles its grammar on every ``pddl.parse_*`` call (about 60 ms); here the
compiled grammar is built once per process for both start symbols (`_grammar`, in memory: the
library writes nothing outside the files it is told to), and a fresh transformer is used per
file, so the library's per-parser state never leaks from one file into the next.
"""

from __future__ import annotations

import codecs
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
from pddl.logic.predicates import Predicate
from pddl.logic.terms import Constant
from pddl.parser import GRAMMAR_FILE, PARSERS_DIRECTORY
from pddl.parser.domain import DomainTransformer
from pddl.parser.problem import ProblemTransformer

from task.errors import PDDLError, one_of
from task.problem import Action, Move

_NUMBER = re.compile(r"^\d+\s*[:.]\s*")  # "0: (pick-up a)" (LPG, LLM plans)
_ACTION = re.compile(r"^\(\s*([^\s()]+)((?:\s+[^\s()]+)*)\s*\)(?:\s*\[[^\]]*\])?$")
_MOVE = re.compile(r"^move\s*\(\s*([^\s(),]+?)\s*(?:->|,)\s*([^\s(),]+)\s*\)$", re.IGNORECASE)
_ARROW = re.compile(r"^([^\s(),]+?)\s*->\s*([^\s(),]+)$")
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


def read_text(path: str | Path) -> str:
    """The text of ``path``: UTF-8 (with or without a byte-order mark) or UTF-16 with its
    byte-order mark (as some Windows editors save); PDDLError naming the file if it is
    missing, unreadable or none of these (a binary file given by mistake: an image, a
    checkpoint, an archive)."""
    try:
        raw = Path(path).read_bytes()
    except FileNotFoundError:
        raise PDDLError(f"{path}: no such file") from None
    except OSError as exc:
        raise PDDLError(f"{path}: cannot read ({exc.strerror or exc})") from None
    utf16 = raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE))
    try:
        text = raw.decode("utf-16" if utf16 else "utf-8-sig")
    except UnicodeDecodeError as exc:
        raise PDDLError(
            f"{path}: not a text file (byte {exc.start} is not "
            f"{'UTF-16' if utf16 else 'UTF-8'}); expected PDDL or plan text"
        ) from None
    if "\x00" in text:  # UTF-16 without its byte-order mark decodes as UTF-8 full of NULs
        raise PDDLError(
            f"{path}: not a text file (byte {raw.index(0)} is NUL: UTF-16 without a "
            "byte-order mark?); expected PDDL or plan text in UTF-8 or UTF-16 with its mark"
        )
    return text.replace("\r\n", "\n").replace("\r", "\n")


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
        tree = _grammar().parse(text, start=start)
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


# --------------------------------------------------------------- PDDL as other tools write it

_KEYWORD = re.compile(
    r"(?<![^\s()])(:[a-z][\w-]*|define|domain|problem|and|or|not|imply|either|object|forall"
    r"|exists|when|oneof|number|increase|decrease|assign|scale-up|scale-down|maximize"
    r"|minimize)(?![^\s()])",
    re.IGNORECASE,
)
_TOKEN = re.compile(r";[^\n]*|\(|\)|[^\s();]+")
_HEADERS = (":requirements", ":types", ":constants", ":predicates", ":functions")
_KNOWN_REQUIREMENTS = frozenset(
    (
        *(":strips", ":typing", ":equality", ":non-deterministic", ":negative-preconditions"),
        *(":disjunctive-preconditions", ":existential-preconditions", ":adl", ":fluents"),
        *(":universal-preconditions", ":quantified-preconditions", ":derived-predicates"),
        *(":conditional-effects", ":numeric-fluents", ":action-costs"),
    )
)


@dataclass(frozen=True)
class _Word:
    text: str
    start: int
    line: int


@dataclass(frozen=True)
class _Node:
    """One parenthesised list of PDDL text: its span (``start`` at ``(``, ``end`` after
    ``)``), the line it opens on and its items (words and lists), comments dropped."""

    start: int
    end: int
    line: int
    items: tuple

    @property
    def head(self) -> str:
        """The first word, lowercased ("" when the list is empty or opens with a list)."""
        first = self.items[0] if self.items else None
        return first.text.lower() if isinstance(first, _Word) else ""


def _read_tree(text: str) -> tuple | None:
    """The top-level lists of ``text`` (None when its parentheses do not balance: the
    parser says where)."""
    stack: list[list] = [[]]
    opened: list[tuple[int, int]] = []
    line = 1
    last = 0
    for match in _TOKEN.finditer(text):
        token, start = match.group(0), match.start()
        line += text.count("\n", last, start)
        last = start
        if token.startswith(";"):
            continue
        if token == "(":
            stack.append([])
            opened.append((start, line))
        elif token == ")":
            if not opened:
                return None
            items, (begin, at) = stack.pop(), opened.pop()
            stack[-1].append(_Node(begin, match.end(), at, tuple(items)))
        else:
            stack[-1].append(_Word(token, start, line))
    return tuple(n for n in stack[0] if isinstance(n, _Node)) if not opened else None


def _define(text: str) -> _Node | None:
    """The ``(define ...)`` list of PDDL text (None if there is none or it does not balance)."""
    tree = _read_tree(text)
    found = [n for n in tree or () if n.head == "define"]
    return found[0] if found else None


def _blank(text: str) -> str:
    """``text`` with every character but newlines made a space (lines and columns kept)."""
    return re.sub(r"[^\n]", " ", text)


def _edit(text: str, edits: list[tuple[int, int, str]]) -> str:
    for start, end, new in sorted(edits, reverse=True):
        text = text[:start] + new + text[end:]
    return text


def _lists(node: _Node):
    """Every list inside ``node``, itself included, depth first."""
    yield node
    for item in node.items:
        if isinstance(item, _Node):
            yield from _lists(item)


def _after(node: _Node, keyword: str) -> object | None:
    """The item after ``keyword`` in ``node`` (an action's ``:precondition``, say)."""
    words = [i for i, x in enumerate(node.items) if isinstance(x, _Word)]
    for i in words:
        if node.items[i].text.lower() == keyword and i + 1 < len(node.items):
            return node.items[i + 1]
    return None


def _requirements(text: str, root: _Node) -> list[tuple[int, int, str]]:
    """Edits that add the requirements a domain uses without declaring (``:typing`` for
    declared types, ``:equality`` for ``=``, ``:action-costs`` for ``(total-cost)``: many
    IPC domains omit them, and Fast Downward and VAL read them anyway) and blank the ones
    this parser does not know (``:durative-actions`` declared, say; a durative action
    itself stays a parse error)."""
    body = " ".join(
        text[n.start : n.end] for n in root.items[2:] if isinstance(n, _Node) and n.head
    )
    body = re.sub(r";[^\n]*", " ", body)
    needs = []
    if re.search(r"\(\s*:types\s*[^\s)]", body):
        needs.append(":typing")
    if re.search(r"\(\s*=\s", body):
        needs.append(":equality")
    if re.search(r"\(\s*total-cost\s*\)", body):
        needs.append(":action-costs")
    section = next((n for n in root.items if isinstance(n, _Node) and n.head == _HEADERS[0]), None)
    edits = []
    declared = set()
    for word in section.items[1:] if section is not None else ():
        declared.add(word.text if isinstance(word, _Word) else "")
        if isinstance(word, _Word) and word.text not in _KNOWN_REQUIREMENTS:
            edits.append((word.start, word.start + len(word.text), _blank(word.text)))
    missing = [r for r in needs if r not in declared]
    if section is not None and len(section.items) - len(edits) > 1:
        where = section.items[0].start + len(section.items[0].text)
        edits.append((where, where, "".join(" " + r for r in missing)))
    elif missing or section is not None:
        if section is not None:
            edits.append((section.start, section.end, _blank(text[section.start : section.end])))
        where = root.items[1].end if len(root.items) > 1 else root.start + 1
        if missing:
            edits.append((where, where, f" (:requirements {' '.join(missing)})"))
    return edits


def _keywords(text: str) -> str:
    """``text`` with PDDL's keywords lowercased and the ``- object`` annotations that end a
    typed list blanked outside ``(:types)``: an untyped name is an object (Tarski's writer
    types everything ``- object``, often with no ``(:types)`` to declare it). A ``- object``
    before another type stays: blanking it would give its names that type."""
    text = _KEYWORD.sub(lambda m: m.group(0).lower(), text)
    edits = []
    for top in _read_tree(text) or ():
        for node in _lists(top):
            if node.head == ":types":
                continue
            items = node.items
            seps = [k for k, w in enumerate(items) if isinstance(w, _Word) and w.text == "-"]
            for k in reversed(seps):
                after = items[k + 1] if k + 1 < len(items) else None
                if not (isinstance(after, _Word) and after.text == "object"):
                    break  # a real type (or an either): the names before it keep theirs
                start, end = items[k].start, after.start + len("object")
                edits.append((start, end, _blank(text[start:end])))
    return _edit(text, edits)


def _domain_style(text: str) -> str:
    """Domain text as the `pddl` grammar reads it, meaning unchanged: keywords lowercased
    (PDDL is case-insensitive; the IPC's files often shout), empty header sections dropped
    (``(:types)``, ``(:constants)``, ``(:functions)``, as Tarski's writer leaves them),
    undeclared requirements implied (`_requirements`), ``:precondition (and)`` for an
    action without one, and the header sections put in the order of the grammar. Lines and
    columns are kept, so parse errors point into the file as written (except where sections
    had to be reordered)."""
    text = _keywords(text)
    root = _define(text)
    if root is None:
        return text
    edits = _requirements(text, root)
    for node in root.items[2:]:
        if not isinstance(node, _Node):
            continue
        if node.head in _HEADERS[1:] and len(node.items) == 1:
            edits.append((node.start, node.end, _blank(text[node.start : node.end])))
        if node.head == ":action" and _after(node, ":precondition") is None:
            params = _after(node, ":parameters")
            if isinstance(params, _Node):
                edits.append((params.end, params.end, " :precondition (and)"))
    text = _edit(text, edits)
    return _in_grammar_order(text)


def _in_grammar_order(text: str) -> str:
    """Domain text with its header sections moved before the actions, in the grammar's order
    (requirements, types, constants, predicates, functions); unchanged when already so."""
    root = _define(text)
    if root is None or len(root.items) < 3:
        return text
    parts = [n for n in root.items[2:] if isinstance(n, _Node)]
    rank = [_HEADERS.index(n.head) if n.head in _HEADERS else len(_HEADERS) for n in parts]
    if rank == sorted(rank):
        return text
    ordered = [n for _, n in sorted(zip(rank, parts, strict=True), key=lambda p: p[0])]
    body = "\n  ".join(text[n.start : n.end] for n in ordered)
    head = text[: root.items[1].end]
    return f"{head}\n  {body})" + text[root.end :]


def _problem_style(text: str) -> str:
    """Problem text as the grammar reads it: keywords lowercased, an empty
    ``(:requirements)`` dropped (lines and columns kept)."""
    text = _keywords(text)
    root = _define(text)
    if root is None:
        return text
    edits = [
        (n.start, n.end, _blank(text[n.start : n.end]))
        for n in root.items[2:]
        if isinstance(n, _Node) and n.head in (":requirements", ":objects") and len(n.items) == 1
    ]
    return _edit(text, edits)


_PRECONDITION = {
    "or": "disjunctive precondition (or)",
    "imply": "disjunctive precondition (imply)",
    "forall": "universal precondition (forall)",
    "exists": "existential precondition (exists)",
    **{op: f"numeric fluent ({op})" for op in (">", "<", ">=", "<=")},
}
_EFFECT = {
    "when": "conditional effect (when)",
    "forall": "universal effect (forall)",
    "oneof": "non-deterministic effect (oneof)",
    **{
        op: f"numeric fluent ({op})"
        for op in ("increase", "decrease", "assign", "scale-up", "scale-down")
    },
}
_GOAL = {**_PRECONDITION, "not": "negative goal (not)"}
_SUPPORTED = "STRIPS: and, atoms, not atoms in effects, = and not = in preconditions"


def _first_beyond(node: object, features: dict[str, str], negative: str | None):
    """The first list under ``node`` whose head is in ``features`` (or a ``not`` of anything
    but ``=``, named ``negative``): ``(list, feature)`` or None."""
    if not isinstance(node, _Node):
        return None
    for inner in _lists(node):
        if inner.head in features:
            return inner, features[inner.head]
        if negative and inner.head == "not":
            arg = inner.items[1] if len(inner.items) > 1 else None
            if not (isinstance(arg, _Node) and arg.head == "="):
                return inner, negative
    return None


def check_strips(text: str, source: str) -> None:
    """PDDLError naming ``source``, the line and the feature of the first construct of domain
    or problem text that the planners cannot plan with (they plan STRIPS with equality):
    derived predicates, negative or disjunctive or quantified preconditions, conditional,
    universal or non-deterministic effects, numeric fluents in actions (action costs
    included), goals beyond a conjunction of atoms. Text that does not balance passes (the
    parser says where)."""
    root = _define(_keywords(text))
    found = None
    for node in root.items[2:] if root is not None else ():
        if not isinstance(node, _Node) or found:
            continue
        if node.head == ":derived":
            found = node, "derived predicate (:derived)"
        elif node.head == ":action":
            pre, eff = _after(node, ":precondition"), _after(node, ":effect")
            found = _first_beyond(pre, _PRECONDITION, "negative precondition (not)")
            found = found or _first_beyond(eff, _EFFECT, None)
        elif node.head == ":goal":
            found = _first_beyond(_after(node, ":goal"), _GOAL, None)
    if found:
        where, feature = found
        snippet = _one_line(text[where.start : where.end])
        snippet = snippet if len(snippet) <= 60 else snippet[:57] + "..."
        raise PDDLError(
            f"{source}: line {where.line}: {feature} {snippet} is not supported "
            f"(supported: {_SUPPORTED})"
        )


def parse_domain(text: str, source: str = "<domain>") -> Domain:
    """Parse domain PDDL text; ``source`` names it in error messages. Text as other tools
    write it is read as they mean it (`_domain_style`: any case, empty sections, undeclared
    requirements)."""
    return _parse(_domain_style(text), "domain", DomainTransformer(), source)


def parse_problem(
    text: str, source: str = "<problem>", domain: Domain | None = None
) -> PDDLProblem:
    """Parse problem PDDL text; if ``domain`` is given, its name must match ``:domain``."""
    problem = _parse(_problem_style(text), "problem", ProblemTransformer(), source)
    if domain is not None and str(problem.domain_name).lower() != str(domain.name).lower():
        raise PDDLError(
            f"{source}: problem {problem.name} is for domain {str(problem.domain_name)!r}, "
            f"not {str(domain.name)!r}"
        )
    if domain is not None:
        _check_names(problem, domain, object_order(text), source)
    return problem


def _predicates_in(formula: object) -> Iterable[Predicate]:
    """Every atom of a formula (through and, or, not, imply, quantifiers), in file order."""
    if isinstance(formula, Predicate):
        yield formula
        return
    for part in getattr(formula, "operands", ()):
        yield from _predicates_in(part)
    for name in ("argument", "condition"):
        if hasattr(formula, name):
            yield from _predicates_in(getattr(formula, name))


def _check_names(problem: PDDLProblem, domain: Domain, order: tuple[str, ...], source: str) -> None:
    """PDDLError (one line naming ``source``) for an ``:init`` or ``:goal`` atom whose predicate
    the domain lacks or takes another number of arguments, or that names an object neither in
    ``:objects`` nor a domain constant: a typo in the goal is bad input, not an unsolvable
    problem. Variables (under a quantifier) are not objects; ``order``: the objects in file order
    (`object_order`), as the valid ones are listed."""
    arity = {str(p.name).lower(): p.arity for p in domain.predicates}
    declared = [str(o.name).lower() for o in (*problem.objects, *domain.constants)]
    objects = list(dict.fromkeys([*order, *sorted(declared)]))
    init = [atom for fact in sorted(problem.init, key=str) for atom in _predicates_in(fact)]
    for where, atoms in (("init", init), ("goal", list(_predicates_in(problem.goal)))):
        for atom in atoms:
            name, terms = str(atom.name).lower(), list(atom.terms)
            text = "(" + " ".join([name, *(str(t.name).lower() for t in terms)]) + ")"
            if name not in arity:
                known = one_of(name, sorted(arity))
                raise PDDLError(f"{source}: {where} atom {text}: unknown predicate {known}")
            if len(terms) != arity[name]:
                raise PDDLError(
                    f"{source}: {where} atom {text}: {name} takes {arity[name]} argument(s), "
                    f"not {len(terms)}"
                )
            for term in terms:
                if isinstance(term, Constant) and str(term.name).lower() not in objects:
                    raise PDDLError(
                        f"{source}: {where} atom {text} names unknown object "
                        f"{one_of(str(term.name).lower(), objects)}"
                    )


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


def problem_with(from_pddl, domain, text: str, source: str = "<problem>"):
    """Problem PDDL ``text`` parsed against ``domain`` and turned into a `Problem` by a domain
    file's ``from_pddl(domain, parsed, order)`` (the file's object order kept); a PDDLError
    of either step names ``source``."""
    parsed = parse_problem(text, source, domain)
    try:
        return from_pddl(domain, parsed, object_order(text))
    except PDDLError as exc:
        raise PDDLError(f"{source}: {exc}") from None
