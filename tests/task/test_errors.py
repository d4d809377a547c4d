"""`task.errors`: the message helpers every one-line error is built with."""

from __future__ import annotations

import enum

import pytest

from task.errors import ProblemError, TampError, member, one_of


def test_one_of_lists_the_valid_names_or_says_there_are_none():
    assert one_of("x", ("a", "b")) == "'x' (valid: a, b)"
    assert one_of("x", []) == "'x' (valid: none)"  # was "(valid: )"


class Colour(enum.StrEnum):
    RED = "red"
    BLUE = "blue"


def test_member_turns_a_name_into_its_mode_and_refuses_others_in_one_line():
    assert member(Colour, "red", "colour") is Colour.RED
    assert member(Colour, Colour.BLUE, "colour") is Colour.BLUE
    with pytest.raises(ProblemError, match=r"^unknown colour 'green' \(valid: red, blue\)$"):
        member(Colour, "green", "colour", ProblemError)
    with pytest.raises(TampError, match=r"^unknown colour \['red'\] \(valid: red, blue\)$"):
        member(Colour, ["red"], "colour")
