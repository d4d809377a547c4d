"""Define a planning domain in PDDL and plan it: the generic soft lift, no code to write.

Any STRIPS domain (no negative preconditions, conditional effects or numeric fluents) plans
through `task.domains.strips`, the soft lift of its grounded actions; the three hand-written
domains (Blocksworld, Logistics, Sokoban) are recognised from their PDDL. A domain with soft
rules of its own is one file in ``task/domains/`` (see docs/extending.md). Here: a robot
carries parcels between rooms. Run: ``python examples/define_domain.py`` (about 5 s).
"""

from __future__ import annotations

from tamp import api

DOMAIN = """
(define (domain courier)
  (:requirements :strips :typing)
  (:types room parcel)
  (:predicates (robot-at ?r - room) (at ?p - parcel ?r - room) (holding ?p - parcel)
               (free) (door ?a - room ?b - room))
  (:action go
    :parameters (?a - room ?b - room)
    :precondition (and (robot-at ?a) (door ?a ?b))
    :effect (and (robot-at ?b) (not (robot-at ?a))))
  (:action take
    :parameters (?p - parcel ?r - room)
    :precondition (and (robot-at ?r) (at ?p ?r) (free))
    :effect (and (holding ?p) (not (at ?p ?r)) (not (free))))
  (:action drop
    :parameters (?p - parcel ?r - room)
    :precondition (and (robot-at ?r) (holding ?p))
    :effect (and (at ?p ?r) (free) (not (holding ?p)))))
"""
PROBLEM = """
(define (problem two-parcels)
  (:domain courier)
  (:objects hall office lab - room p1 p2 - parcel)
  (:init (robot-at hall) (free) (at p1 hall) (at p2 lab)
         (door hall office) (door office hall) (door office lab) (door lab office))
  (:goal (and (at p1 lab) (at p2 hall))))
"""


def main() -> None:
    print(f"rules that plan it: {api.domain_rules(DOMAIN)} (of {', '.join(api.domain_names())})")
    task = api.load_problem(PROBLEM, DOMAIN)
    planned = api.plan(task, seed=0)
    print(planned.text(), end="")
    print(f"{planned.status.value}: {planned.validation.reason}")
    assert planned.valid


if __name__ == "__main__":
    main()
