"""PDDL text as nested lists: words and parenthesised lists with their offsets and lines.

The styles (`task.symbolic.pddl_io.style`) and the STRIPS check
(`task.symbolic.pddl_io.strips_check`) read PDDL text through these lists before the grammar
sees it, so that they can edit the text in place and name the line of a construct. Comments are
dropped; lines and columns of the text are kept by every edit here.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_TOKEN = re.compile(r";[^\n]*|\(|\)|[^\s();]+")


@dataclass(frozen=True)
class Word:
    """One word of PDDL text: its text, its offset and its line."""

    text: str
    start: int
    line: int


@dataclass(frozen=True)
class Node:
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
        return first.text.lower() if isinstance(first, Word) else ""


def read_tree(text: str) -> tuple | None:
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
            stack[-1].append(Node(begin, match.end(), at, tuple(items)))
        else:
            stack[-1].append(Word(token, start, line))
    return tuple(n for n in stack[0] if isinstance(n, Node)) if not opened else None


def define(text: str) -> Node | None:
    """The ``(define ...)`` list of PDDL text (None if there is none or it does not balance)."""
    tree = read_tree(text)
    found = [n for n in tree or () if n.head == "define"]
    return found[0] if found else None


def blank(text: str) -> str:
    """``text`` with every character but newlines made a space (lines and columns kept)."""
    return re.sub(r"[^\n]", " ", text)


def edit(text: str, edits: list[tuple[int, int, str]]) -> str:
    for start, end, new in sorted(edits, reverse=True):
        text = text[:start] + new + text[end:]
    return text


def lists(node: Node):
    """Every list inside ``node``, itself included, depth first."""
    yield node
    for item in node.items:
        if isinstance(item, Node):
            yield from lists(item)


def after(node: Node, keyword: str) -> object | None:
    """The item after ``keyword`` in ``node`` (an action's ``:precondition``, say)."""
    words = [i for i, x in enumerate(node.items) if isinstance(x, Word)]
    for i in words:
        if node.items[i].text.lower() == keyword and i + 1 < len(node.items):
            return node.items[i + 1]
    return None
