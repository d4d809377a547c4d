"""The declared binding of a pick-and-place PDDL domain to the motion layer.

A user's domain names its own actions and arguments; the motion layer carries one object at a
time onto a target (another object, or a region such as a peg, a tray or the table). The
binding says, per action, its role and which argument is what:

- ``pick``: takes ``object`` into the hand (``pick-up ?x``, ``unstack ?x ?y``);
- ``place``: puts the held ``object`` onto ``target`` (``stack ?x ?y``; ``put-down ?x`` onto the
  fixed region ``table``);
- ``move``: both at once (Hanoi's ``move ?d ?from ?to``).

``object`` is a parameter (``"?x"``); ``target`` is a parameter or, without the ``?``, a fixed
region the action always places on. A binding is declared as a tiny JSON or TOML text::

    {"domain": "blocksworld-4ops",
     "actions": {"pick-up": {"role": "pick", "object": "?x"},
                 "stack": {"role": "place", "object": "?x", "target": "?y"}, ...}}

`load_text` reads it into a `BindingSpec` (what was declared); `bind` checks it against the
domain's action schemas and returns a `Binding`: an unknown action, argument, role or key, and
an action that neither picks nor places what it names, are one-line `BindingError`s listing
the valid names. The schema checks are structural: a pick adds an atom of its object (the
hold, e.g. ``(holding ?x)``) and needs none that a pick adds; a place needs and deletes such a
hold and adds an atom of its object (with its target, when the target is a parameter); a move
deletes an atom of its object and adds one of object and target. `to_moves` pairs a plan's
actions into `task.problem.Move`s (object -> target): a pick must be followed by the place of
the same object; anything else is a one-line error naming the plan step.

An optional ``scene`` section says how a scene's geometry reads as the domain's initial state
(``tamp run --scene FILE --domain D.pddl --binding B.json``; the robot reads the state, it is
never given): the PDDL types of the scene's movable objects and regions, and which predicate
holds each geometric relation (`RELATIONS`)::

    "scene": {"objects": "disc", "regions": "peg",
              "facts": {"on": "on", "in": "on", "clear": "clear", "empty": "clear",
                        "narrower": "smaller", "fits": "smaller"}}

Each predicate must exist in the domain with the relation's arity; a relation left out is not
written, and an object whose support is such a relation is refused when the problem is written
(`tamp.world.scene_pddl`).
"""

from __future__ import annotations

import enum
import json
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from pddl.core import Domain

from task.errors import ProblemError, one_of
from task.problem import Action, Move
from task.symbolic import strips


class BindingError(ProblemError):
    """A binding names what the domain lacks, or declares a role its action cannot play."""


class Role(enum.Enum):
    PICK = "pick"
    PLACE = "place"
    MOVE = "move"  # pick and place in one action


ROLES = tuple(r.value for r in Role)
KEYS = ("role", "object", "target")
TOP_KEYS = ("domain", "actions", "scene")
SCENE_KEYS = ("objects", "regions", "facts")
# the geometric relations a scene is read as (`tamp.world.scene_pddl`) and their arities:
# object x on object y, x in region r, x on the bare table, nothing on object x, nothing in
# region r, x's footprint narrower than object y's, x's footprint fits inside region r, the
# hand empty (true when a problem starts)
RELATIONS = {
    "on": 2,
    "in": 2,
    "ontable": 1,
    "clear": 1,
    "empty": 1,
    "narrower": 2,
    "fits": 2,
    "handempty": 0,
}

# the embedded 4-op blocksworld (`task/data/blocksworld-4ops.pddl`): put-down places on the table
BLOCKSWORLD = """{
  "domain": "blocksworld-4ops",
  "actions": {
    "pick-up": {"role": "pick", "object": "?x"},
    "unstack": {"role": "pick", "object": "?x"},
    "put-down": {"role": "place", "object": "?x", "target": "table"},
    "stack": {"role": "place", "object": "?x", "target": "?y"}
  }
}"""


@dataclass(frozen=True)
class ActionSpec:
    """One declared action: its role, its object parameter (``?x``) and its target (a
    parameter ``?y``, a fixed region name, or None for a pick)."""

    role: Role
    object: str
    target: str | None = None


@dataclass(frozen=True)
class SceneFacts:
    """The declared reading of a scene as the domain's state: the PDDL types of its objects
    and regions (None: untyped) and the predicate of each geometric relation
    (`RELATIONS`) written."""

    objects: str | None = None
    regions: str | None = None
    facts: tuple[tuple[str, str], ...] = ()

    def predicate(self, relation: str) -> str | None:
        """The domain's predicate holding ``relation``, None when it is not written."""
        return dict(self.facts).get(relation)


@dataclass(frozen=True)
class BindingSpec:
    """A binding as declared, before it is checked against a domain (``domain``: the PDDL
    domain name it is for, None: any; ``scene``: how a scene reads as its state, if said)."""

    actions: tuple[tuple[str, ActionSpec], ...]
    domain: str | None = None
    scene: SceneFacts | None = None


@dataclass(frozen=True)
class BoundAction:
    """A checked action: ``object`` the index of its object argument; ``target`` the index of
    its target argument, or the fixed region's name, or None (a pick)."""

    name: str
    role: Role
    object: int
    target: int | str | None


@dataclass(frozen=True)
class Binding:
    """A binding checked against the action schemas of domain ``domain`` (``scene``: its
    checked `SceneFacts`, None when the binding says none)."""

    domain: str
    actions: tuple[BoundAction, ...]
    scene: SceneFacts | None = None

    def get(self, name: str) -> BoundAction | None:
        return next((a for a in self.actions if a.name == name.lower()), None)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.actions)


# ------------------------------------------------------------------------------ declaration


def _table(entry: object, keys: tuple[str, ...], where: str) -> None:
    """BindingError unless ``entry`` is a table whose keys are among ``keys``."""
    if not isinstance(entry, Mapping):
        raise BindingError(f"{where}: expected a table of {', '.join(keys)}, got {entry!r}")
    for key in entry:
        if key not in keys:
            raise BindingError(f"{where}: unknown key {one_of(key, keys)}")


def _action_spec(name: str, entry: object, source: str) -> ActionSpec:
    where = f"{source}: action {name}"
    _table(entry, KEYS, where)
    for key in KEYS:
        value = entry.get(key)
        if key != "target" and value is None:
            raise BindingError(f"{where}: missing {key!r}")
        if value is not None and (not isinstance(value, str) or not value.strip("?")):
            raise BindingError(f"{where}: {key} must be a name, got {value!r}")
    if entry["role"] not in ROLES:
        raise BindingError(f"{where}: unknown role {one_of(entry['role'], ROLES)}")
    role = Role(entry["role"])
    target = entry.get("target")
    if role is Role.PICK and target is not None:
        raise BindingError(f"{where}: a pick names no target (its place does), got {target!r}")
    if role is not Role.PICK and target is None:
        raise BindingError(f"{where}: a {role.value} needs a target (a ?parameter or a region)")
    return ActionSpec(role, entry["object"].lower(), target and target.lower())


def from_mapping(data: object, source: str = "<binding>") -> BindingSpec:
    """The `BindingSpec` of a decoded JSON or TOML document."""
    if not isinstance(data, Mapping):
        raise BindingError(f"{source}: expected a table with 'actions', got {type(data).__name__}")
    for key in data:
        if key not in TOP_KEYS:
            raise BindingError(f"{source}: unknown key {one_of(key, TOP_KEYS)}")
    actions = data.get("actions")
    if not isinstance(actions, Mapping) or not actions:
        raise BindingError(f"{source}: 'actions' must map at least one action to its role")
    domain = data.get("domain")
    if domain is not None and not isinstance(domain, str):
        raise BindingError(f"{source}: 'domain' must be a name, got {domain!r}")
    specs = tuple((str(n).lower(), _action_spec(str(n), e, source)) for n, e in actions.items())
    scene = None if data.get("scene") is None else _scene_facts(data["scene"], source)
    return BindingSpec(specs, domain and domain.lower(), scene)


def _scene_facts(entry: object, source: str) -> SceneFacts:
    where = f"{source}: scene"
    _table(entry, SCENE_KEYS, where)
    for key in ("objects", "regions"):
        value = entry.get(key)
        if value is not None and (not isinstance(value, str) or not value):
            raise BindingError(f"{where}: {key} must be a PDDL type name, got {value!r}")
    facts = entry.get("facts")
    if not isinstance(facts, Mapping) or not facts:
        raise BindingError(
            f"{where}: 'facts' must map geometric relations ({', '.join(RELATIONS)}) to the "
            "domain's predicates"
        )
    pairs = []
    for relation, predicate in facts.items():
        if relation not in RELATIONS:
            raise BindingError(f"{where}: unknown relation {one_of(relation, tuple(RELATIONS))}")
        if not isinstance(predicate, str) or not predicate:
            raise BindingError(f"{where}: {relation} must name a predicate, got {predicate!r}")
        pairs.append((relation, predicate.lower()))
    objects, regions = entry.get("objects"), entry.get("regions")
    return SceneFacts(objects and objects.lower(), regions and regions.lower(), tuple(pairs))


def decode(text: str, fmt: str = "json", source: str = "<binding>") -> object:
    """The document of JSON (``fmt="json"``) or TOML (``fmt="toml"``) binding text, before
    its declarations are checked (`from_mapping`)."""
    if fmt not in ("json", "toml"):
        raise BindingError(f"{source}: unknown binding format {one_of(fmt, ('json', 'toml'))}")
    try:
        return json.loads(text) if fmt == "json" else tomllib.loads(text)
    except (json.JSONDecodeError, tomllib.TOMLDecodeError) as exc:
        first = str(exc).splitlines()[0]
        raise BindingError(f"{source}: not valid {fmt.upper()}: {first}") from None


def load_text(text: str, fmt: str = "json", source: str = "<binding>") -> BindingSpec:
    """Read a binding from JSON (``fmt="json"``) or TOML (``fmt="toml"``) text."""
    return from_mapping(decode(text, fmt, source), source)


def read(path: str | Path) -> tuple[str, str]:
    """The text of binding file ``path`` and its format, ``json`` or ``toml`` by its suffix;
    BindingError for another suffix or a file that cannot be read."""
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    if fmt not in ("json", "toml"):
        raise BindingError(
            f"{path}: a binding file ends in {one_of(path.suffix, ('.json', '.toml'))}"
        )
    try:
        return path.read_text(encoding="utf-8"), fmt
    except OSError as exc:
        raise BindingError(f"{path}: cannot read the binding ({exc.strerror})") from None


def load(path: str | Path) -> BindingSpec:
    """Read a binding file: ``.json`` or ``.toml``."""
    text, fmt = read(path)
    return load_text(text, fmt, str(path))


# ---------------------------------------------------------------------------------- checking


def _schema_atoms(domain: Domain, name: str) -> tuple[list, list, list]:
    """The (pre, add, delete) atoms of action ``name``'s schema, parameters as ``?p``."""
    schema = {str(a.name).lower(): a for a in domain.actions}[name]
    params = {str(p.name).lower(): f"?{str(p.name).lower()}" for p in schema.parameters}
    pre = strips.flat_literals(schema.precondition, f"action {name}: precondition")
    eff = strips.flat_literals(schema.effect, f"action {name}: effect")
    pre_atoms = [strips.atom_of(p, params) for positive, p in pre if positive]
    add = [strips.atom_of(p, params) for positive, p in eff if positive]
    delete = [strips.atom_of(p, params) for positive, p in eff if not positive]
    return pre_atoms, add, delete


def _of(atoms: list, *args: str) -> list:
    """The atoms that name every one of ``args``."""
    return [a for a in atoms if all(x in a[1:] for x in args)]


def _both(atoms: tuple[list, list, list]) -> list:
    """The precondition atoms an action also deletes."""
    pre, _, delete = atoms
    return [a for a in pre if a in delete]


def _shape(atom: tuple, obj: str) -> tuple:
    """An atom with its object written ``?`` and its other parameters ``*``: the holds of
    different actions compare alike whatever they call their parameters."""
    return tuple("?" if x == obj else "*" if x.startswith("?") else x for x in atom)


def bind(spec: BindingSpec, domain: Domain) -> Binding:
    """Check ``spec`` against ``domain``'s action schemas (see the module docstring)."""
    dname = str(domain.name).lower()
    if spec.domain is not None and spec.domain != dname:
        raise BindingError(f"binding is for domain {spec.domain!r}, not {dname!r}")
    schemas = {str(a.name).lower(): a for a in domain.actions}
    bound, atoms = [], {}
    for name, entry in spec.actions:
        if name not in schemas:
            raise BindingError(f"binding: unknown action {one_of(name, sorted(schemas))}")
        params = tuple(f"?{str(p.name).lower()}" for p in schemas[name].parameters)
        if entry.object not in params:
            raise BindingError(f"binding: action {name}: object {one_of(entry.object, params)}")
        target: int | str | None = entry.target
        if entry.target is not None and entry.target.startswith("?"):
            if entry.target not in params:
                what = one_of(entry.target, params)
                raise BindingError(f"binding: action {name}: target {what} (or a region name)")
            if entry.target == entry.object:
                raise BindingError(f"binding: action {name}: {entry.object} is object and target")
            target = params.index(entry.target)
        atoms[name] = _schema_atoms(domain, name)
        bound.append(BoundAction(name, entry.role, params.index(entry.object), target))
    if spec.scene is not None:
        _check_scene(spec.scene, domain)
    binding = Binding(dname, tuple(bound), spec.scene)
    _check_roles(binding, spec, atoms)
    return binding


def _check_scene(scene: SceneFacts, domain: Domain) -> None:
    """BindingError for a scene section naming a type or predicate the domain lacks, or a
    predicate of another arity than its relation's."""
    types = sorted(str(t).lower() for t in domain.types)
    for key in ("objects", "regions"):
        name = getattr(scene, key)
        if name is not None and name != "object" and name not in types:
            raise BindingError(f"binding: scene {key}: unknown type {one_of(name, types)}")
    arity = {str(p.name).lower(): p.arity for p in domain.predicates}
    for relation, predicate in scene.facts:
        if predicate not in arity:
            what = one_of(predicate, sorted(arity))
            raise BindingError(f"binding: scene fact {relation}: unknown predicate {what}")
        if arity[predicate] != RELATIONS[relation]:
            raise BindingError(
                f"binding: scene fact {relation}: ({predicate}) takes {arity[predicate]} "
                f"argument(s), {relation} gives {RELATIONS[relation]}"
            )


def _check_roles(binding: Binding, spec: BindingSpec, atoms: dict) -> None:
    """BindingError for an action whose schema cannot play its declared role."""
    entries = dict(spec.actions)
    picks = [a for a in binding.actions if a.role is Role.PICK]
    places = [a for a in binding.actions if a.role is Role.PLACE]
    if bool(picks) != bool(places):
        have, lacks = ("pick", "place") if picks else ("place", "pick")
        names = ", ".join(a.name for a in picks or places)
        raise BindingError(f"binding has {have} actions ({names}) but no {lacks} action")

    def shapes(action: BoundAction, atoms_: list) -> set:
        return {_shape(a, entries[action.name].object) for a in atoms_}

    # the hold: an atom of its object that a pick adds and a place needs and deletes
    made = set().union(*(shapes(a, _of(atoms[a.name][1], entries[a.name].object)) for a in picks))
    used = set().union(
        *(shapes(a, _of(_both(atoms[a.name]), entries[a.name].object)) for a in places)
    )
    holds = made & used
    for action in binding.actions:
        entry = entries[action.name]
        pre, add, delete = atoms[action.name]
        obj, target = entry.object, entry.target
        held = [a for a in _of(pre, obj) if _shape(a, obj) in holds]
        if action.role is not Role.PLACE and held:
            raise BindingError(
                f"binding: action {action.name} ({action.role.value}) needs "
                f"{strips.atom_str(held[0])}, which a pick makes: it places, it does not pick"
            )
        if action.role is Role.PICK and not [a for a in _of(add, obj) if _shape(a, obj) in holds]:
            raise BindingError(
                f"binding: action {action.name} (pick) adds no atom of {obj} that a place needs "
                f"and deletes: it picks nothing a place puts down"
            )
        if not _of(add, obj):
            raise BindingError(
                f"binding: action {action.name} neither picks nor places {obj}: "
                f"it adds no atom of {obj}"
            )
        if action.role is Role.PLACE and not [a for a in held if a in delete]:
            raise BindingError(
                f"binding: action {action.name} (place) needs and deletes no atom of {obj} that "
                f"a pick adds: it places nothing that was picked"
            )
        if action.role is not Role.PICK and target.startswith("?") and not _of(add, obj, target):
            raise BindingError(
                f"binding: action {action.name} ({action.role.value}) adds no atom of "
                f"{obj} and {target}: it does not place {obj} on {target}"
            )
        if action.role is Role.MOVE and not _of(delete, obj):
            raise BindingError(
                f"binding: action {action.name} (move) deletes no atom of {obj}: "
                f"it does not take {obj} from anywhere"
            )


def bind_text(text: str, domain: Domain, fmt: str = "json", source: str = "<binding>") -> Binding:
    """`bind` of a binding text."""
    return bind(load_text(text, fmt, source), domain)


# -------------------------------------------------------------------------------------- plans


def to_moves(binding: Binding, plan: Sequence[Action]) -> tuple[Move, ...]:
    """The ``(object -> target)`` moves of a validated plan, in order (see the module
    docstring); BindingError naming the 1-based plan step otherwise."""
    moves: list[Move] = []
    held: tuple[str, int] | None = None  # (object, the step that picked it)
    for step, action in enumerate(plan, start=1):
        where = f"plan step {step} {action}"
        bound = binding.get(action.name)
        if bound is None:
            bound_names = ", ".join(binding.names)
            raise BindingError(f"{where}: neither picks nor places (bound: {bound_names})")
        args = tuple(a.lower() for a in action.args)
        needs = max(i for i in (bound.object, bound.target, 0) if isinstance(i, int)) + 1
        if len(args) < needs:
            raise BindingError(f"{where}: {bound.name} needs {needs} arguments, got {len(args)}")
        obj = args[bound.object]
        if bound.role is Role.PICK:
            if held is not None:
                raise BindingError(
                    f"{where}: the hand holds {held[0]} (picked at step {held[1]}); "
                    f"a pick must be followed by its place"
                )
            held = (obj, step)
            continue
        if bound.role is Role.PLACE and held is None:
            raise BindingError(f"{where}: places {obj}, which no pick holds")
        if bound.role is Role.PLACE and held[0] != obj:
            raise BindingError(
                f"{where}: places {obj}, but the hand holds {held[0]} (picked at step {held[1]})"
            )
        if bound.role is Role.MOVE and held is not None:
            raise BindingError(
                f"{where}: moves {obj} while the hand holds {held[0]} (picked at step {held[1]})"
            )
        target = args[bound.target] if isinstance(bound.target, int) else bound.target
        moves.append(Move(obj, target))
        held = None
    if held is not None:
        raise BindingError(f"plan ends holding {held[0]} (picked at step {held[1]}), unplaced")
    return tuple(moves)
