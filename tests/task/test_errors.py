"""`task.errors`: the message helpers every one-line error is built with."""

from __future__ import annotations

from task.errors import one_of


def test_one_of_lists_the_valid_names_or_says_there_are_none():
    assert one_of("x", ("a", "b")) == "'x' (valid: a, b)"
    assert one_of("x", []) == "'x' (valid: none)"  # was "(valid: )"
