"""PDDL as other tools write it, read as they mean it before the `pddl` grammar sees it.

Keywords in any case, empty sections (Tarski's writer leaves ``(:types)``, ``(:constants)``,
``(:functions)`` empty), requirements used but not declared or declared but unknown here,
``- object`` annotations, header sections out of order, actions without a precondition
(`domain_style`, `problem_style`); lines and columns are kept for parse errors.
"""

from __future__ import annotations

import re

from task.symbolic.pddl_io.tree import Node, Word, after, blank, define, edit, lists, read_tree

_KEYWORD = re.compile(
    r"(?<![^\s()])(:[a-z][\w-]*|define|domain|problem|and|or|not|imply|either|object|forall"
    r"|exists|when|oneof|number|increase|decrease|assign|scale-up|scale-down|maximize"
    r"|minimize)(?![^\s()])",
    re.IGNORECASE,
)
_HEADERS = (":requirements", ":types", ":constants", ":predicates", ":functions")
_KNOWN_REQUIREMENTS = frozenset(
    (
        *(":strips", ":typing", ":equality", ":non-deterministic", ":negative-preconditions"),
        *(":disjunctive-preconditions", ":existential-preconditions", ":adl", ":fluents"),
        *(":universal-preconditions", ":quantified-preconditions", ":derived-predicates"),
        *(":conditional-effects", ":numeric-fluents", ":action-costs"),
    )
)


def _requirements(text: str, root: Node) -> list[tuple[int, int, str]]:
    """Edits that add the requirements a domain uses without declaring (``:typing`` for
    declared types, ``:equality`` for ``=``, ``:action-costs`` for ``(total-cost)``: many
    IPC domains omit them, and Fast Downward and VAL read them anyway) and blank the ones
    this parser does not know (``:durative-actions`` declared, say; a durative action
    itself stays a parse error)."""
    body = " ".join(text[n.start : n.end] for n in root.items[2:] if isinstance(n, Node) and n.head)
    body = re.sub(r";[^\n]*", " ", body)
    needs = []
    if re.search(r"\(\s*:types\s*[^\s)]", body):
        needs.append(":typing")
    if re.search(r"\(\s*=\s", body):
        needs.append(":equality")
    if re.search(r"\(\s*total-cost\s*\)", body):
        needs.append(":action-costs")
    section = next((n for n in root.items if isinstance(n, Node) and n.head == _HEADERS[0]), None)
    edits = []
    declared = set()
    for word in section.items[1:] if section is not None else ():
        declared.add(word.text if isinstance(word, Word) else "")
        if isinstance(word, Word) and word.text not in _KNOWN_REQUIREMENTS:
            edits.append((word.start, word.start + len(word.text), blank(word.text)))
    missing = [r for r in needs if r not in declared]
    if section is not None and len(section.items) - len(edits) > 1:
        where = section.items[0].start + len(section.items[0].text)
        edits.append((where, where, "".join(" " + r for r in missing)))
    elif missing or section is not None:
        if section is not None:
            edits.append((section.start, section.end, blank(text[section.start : section.end])))
        where = root.items[1].end if len(root.items) > 1 else root.start + 1
        if missing:
            edits.append((where, where, f" (:requirements {' '.join(missing)})"))
    return edits


def keywords(text: str) -> str:
    """``text`` with PDDL's keywords lowercased and the ``- object`` annotations that end a
    typed list blanked outside ``(:types)``: an untyped name is an object (Tarski's writer
    types everything ``- object``, often with no ``(:types)`` to declare it). A ``- object``
    before another type stays: blanking it would give its names that type."""
    text = _KEYWORD.sub(lambda m: m.group(0).lower(), text)
    edits = []
    for top in read_tree(text) or ():
        for node in lists(top):
            if node.head == ":types":
                continue
            items = node.items
            seps = [k for k, w in enumerate(items) if isinstance(w, Word) and w.text == "-"]
            for k in reversed(seps):
                after = items[k + 1] if k + 1 < len(items) else None
                if not (isinstance(after, Word) and after.text == "object"):
                    break  # a real type (or an either): the names before it keep theirs
                start, end = items[k].start, after.start + len("object")
                edits.append((start, end, blank(text[start:end])))
    return edit(text, edits)


def domain_style(text: str) -> str:
    """Domain text as the `pddl` grammar reads it, meaning unchanged: keywords lowercased
    (PDDL is case-insensitive; the IPC's files often shout), empty header sections dropped
    (``(:types)``, ``(:constants)``, ``(:functions)``, as Tarski's writer leaves them),
    undeclared requirements implied (`_requirements`), ``:precondition (and)`` for an
    action without one, and the header sections put in the order of the grammar. Lines and
    columns are kept, so parse errors point into the file as written (except where sections
    had to be reordered)."""
    text = keywords(text)
    root = define(text)
    if root is None:
        return text
    edits = _requirements(text, root)
    for node in root.items[2:]:
        if not isinstance(node, Node):
            continue
        if node.head in _HEADERS[1:] and len(node.items) == 1:
            edits.append((node.start, node.end, blank(text[node.start : node.end])))
        if node.head == ":action" and after(node, ":precondition") is None:
            params = after(node, ":parameters")
            if isinstance(params, Node):
                edits.append((params.end, params.end, " :precondition (and)"))
    text = edit(text, edits)
    return _in_grammar_order(text)


def _in_grammar_order(text: str) -> str:
    """Domain text with its header sections moved before the actions, in the grammar's order
    (requirements, types, constants, predicates, functions); unchanged when already so."""
    root = define(text)
    if root is None or len(root.items) < 3:
        return text
    parts = [n for n in root.items[2:] if isinstance(n, Node)]
    rank = [_HEADERS.index(n.head) if n.head in _HEADERS else len(_HEADERS) for n in parts]
    if rank == sorted(rank):
        return text
    ordered = [n for _, n in sorted(zip(rank, parts, strict=True), key=lambda p: p[0])]
    body = "\n  ".join(text[n.start : n.end] for n in ordered)
    head = text[: root.items[1].end]
    return f"{head}\n  {body})" + text[root.end :]


def problem_style(text: str) -> str:
    """Problem text as the grammar reads it: keywords lowercased, an empty
    ``(:requirements)`` dropped (lines and columns kept)."""
    text = keywords(text)
    root = define(text)
    if root is None:
        return text
    edits = [
        (n.start, n.end, blank(text[n.start : n.end]))
        for n in root.items[2:]
        if isinstance(n, Node) and n.head in (":requirements", ":objects") and len(n.items) == 1
    ]
    return edit(text, edits)
