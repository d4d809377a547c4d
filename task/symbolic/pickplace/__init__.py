"""task.symbolic.pickplace: a user's own pick-and-place PDDL domain, bound to the motion layer.

- ``binding``: the declared mapping (action -> pick / place / move, argument -> object /
  target), read from a small JSON or TOML text, checked against the domain's action schemas,
  and the pairing of a validated plan's actions into ``(object, target)`` moves;
- ``hanoi``: Tower of Hanoi (`task/data/hanoi.pddl`), the example such domain: seeded problems
  of discs on three pegs (regions), and the binding of its ``move``.

Crisp like the rest of `task.symbolic`: no torch, no domain module.
"""
