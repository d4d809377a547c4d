"""Known structure, whatever its names: a PDDL domain matched to a hand-written one by shape.

A user's domain that is a hand-written domain (`task.domains` registry) up to renaming of its
predicates, actions, parameter order, types and constants (unused extra predicates and
constants allowed) is planned with that domain's soft rules; plans and messages keep the
user's names. The match is structural, never by name: action signatures, and precondition,
add and delete lists as sets of atom shapes over parameter positions.

- ``schema``: a parsed domain as plain data (`Shape`, `Schema`);
- ``search``: the backtracking bijection between two shapes, with defects for near misses;
- ``renaming``: the `Renaming` value, both ways, and the wrappers that make a domain's
  ``to_actions``/``to_atoms`` speak the user's names;
- ``recognise``: `match_domain` -> `Match` | `NearMiss` | None, over the registered domains;
  `recognise`: the name of the domain's rules (a match's, else the generic lift);
- ``problem``: a user's problem read as the hand-written domain's (`to_reference`);
- ``rename``: seeded random renamings of a domain and its problems (tests, benchmarks).
"""

from task.domains.match.problem import to_reference
from task.domains.match.recognise import Match, NearMiss, match_domain, recognise
from task.domains.match.rename import RenamedFiles, rename, rename_folder
from task.domains.match.renaming import Renamed, Renaming

__all__ = [
    "Match",
    "NearMiss",
    "Renamed",
    "RenamedFiles",
    "Renaming",
    "match_domain",
    "recognise",
    "rename",
    "rename_folder",
    "to_reference",
]
