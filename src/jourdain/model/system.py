"""The immutable, validated model: coordinates, parameters, inputs, bodies and force elements.

Pure data: the stages of the method take a System (:mod:`jourdain.stages`), and
:class:`jourdain.System` (:mod:`jourdain.pipeline`) adds them as cached methods; nothing here
imports them (docs/architecture.md)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Self

import symengine as se

from ..errors import ModelError
from .bodies import Body, BodyGroup, expand_groups
from .closing import ClosingJoint, grubler
from .contacts import CONTACT_TYPES, Contact, check_linear
from .expressions import as_expr, magnitude_problem, t
from .forces import (
    Bushing,
    Force,
    ForceElement,
    GeneralizedForce,
    Gravity,
    SpringDamper,
    Torque,
    acceleration,
    rate,
)
from .friction import JointFriction, check_frictions, split_frictions
from .quantities import Quantity, quantities_in
from .validation import force_expressions, parents_first, validate


def _symbol_list(items: Iterable[object] | str, what: str) -> tuple[se.Symbol, ...]:
    if isinstance(items, str):
        items = items.replace(",", " ").split()
    out = []
    for it in items:
        s = se.Symbol(it) if isinstance(it, str) else as_expr(it, what)
        if not isinstance(s, se.Symbol):
            raise ModelError(f"{what}: expected a symbol or a name, got {it!r}")
        if not str(s).isidentifier():
            raise ModelError(f"{what}: {str(s)!r} is not a valid name")
        out.append(s)
    return tuple(out)


@dataclass(frozen=True, eq=True)
class System:
    """A multibody system of rigid bodies in a tree of joints (immutable once built).

    Parameters
    ----------
    coordinates : sequence of symbols or names
        The generalized coordinates ``y`` (f of them). Their rates are named ``<name>_d``.
    bodies : sequence of Body or BodyGroup
        Each hangs from ``"world"`` or from another body through its joint. The order is kept:
        it is the order of :attr:`bodies`, of the body rows of M̄, J̄, q̄^c, q̄^e and of the
        joints in the reactions g. Every parent must come before its children (any such order
        is valid for the method); a child listed before its parent raises a ModelError naming
        both and their positions. A :class:`~jourdain.model.bodies.BodyGroup` (an elastic
        body) is expanded in its place into its bodies; its coordinates join ``y`` (after
        those given, unless listed) and its force elements the forces (:attr:`groups`).
    forces : sequence of force elements
        Gravity, Force, Torque, SpringDamper, GeneralizedForce (RotationalSpringDamper),
        Bushing. Their laws may use kinematic quantities
        (:mod:`jourdain.model.quantities`), found from their symbols: :attr:`quantities`.
        :class:`~jourdain.model.friction.JointFriction` elements (friction from the reactions)
        are kept apart, as :attr:`frictions`.
    parameters : mapping name -> default value
        Every symbol in the model other than coordinates, rates, inputs and ``t``.
    inputs : sequence of symbols or names
        Input symbols ``u`` (actuator forces, excitations), given as functions of time when
        simulating.
    units : mapping name -> unit string, optional
        Units of parameters and coordinates, for reports.
    name : str
    closing : sequence of ClosingJoint, optional
        Joints that close kinematic loops of the tree (METHOD.md §7). With any, the system is
        closed: its coordinates ``y`` are the tree's (f of them), tied by the closing joints'
        rows ``Φ(y, t) = 0``, and every stage and function works on the closed mechanism; the
        open tree is :attr:`tree`.
    independent : sequence of coordinate names, optional
        The independent coordinates of a closed system (else chosen by pivoting on ``Φ_y`` at
        the initial configuration).
    contacts : sequence of RollingDisc, KnifeEdge, VelocityConstraint, optional
        Velocity (nonholonomic) constraints ``A·ẏ + a = 0`` (METHOD.md §7, ``docs/rolling.md``):
        with any, the system is a *general* one, moving with ``g = f − r`` generalized
        velocities ``z`` (:attr:`speeds`), ``ẏ = L·z + l``.
    speeds : sequence of names, or mapping name -> expression, optional
        The generalized velocities z: coordinate names (``z`` their rates), or definitions
        ``z_k = Y_k(y, t)·ẏ + b_k`` (expressions linear in the rates ``<coordinate>_d``, e.g. a
        body-fixed angular velocity component). Else chosen by pivoting on the velocity rows.
    """

    coordinates: tuple[se.Symbol, ...]
    bodies: tuple[Body, ...]
    forces: tuple[ForceElement, ...]
    parameters: tuple[tuple[str, float], ...]
    inputs: tuple[se.Symbol, ...]
    units: tuple[tuple[str, str], ...]
    name: str
    quantities: tuple[Quantity, ...]
    closing: tuple[ClosingJoint, ...] = ()
    independent: tuple[str, ...] | None = None
    contacts: tuple[Contact, ...] = ()
    speeds: tuple[tuple[str, se.Basic], ...] | None = None
    frictions: tuple[JointFriction, ...] = ()
    groups: tuple[BodyGroup, ...] = ()

    def __init__(self, coordinates: Sequence[object] | str,
                 bodies: Sequence[Body | BodyGroup],
                 forces: Sequence[ForceElement | JointFriction | object] = (), parameters: Mapping[str, float] | None = None,
                 inputs: Sequence[object] | str = (), units: Mapping[str, str] | None = None,
                 name: str = "system", closing: Sequence[ClosingJoint] = (),
                 independent: Sequence[str] | None = None, contacts: Sequence[Contact] = (),
                 speeds: Sequence[str] | Mapping[str, object] | None = None) -> None:
        y, body_list, force_list, groups = expand_groups(
            _symbol_list(coordinates, "coordinates"), bodies, forces)
        u = _symbol_list(inputs, "inputs")
        params = dict(parameters or {})
        set_ = object.__setattr__
        set_(self, "name", str(name))
        set_(self, "coordinates", y)
        set_(self, "inputs", u)
        pvals: list[tuple[str, float]] = []
        for k, v in params.items():
            if not isinstance(k, str) or not k.isidentifier():
                raise ModelError(f"parameter name {k!r} must be an identifier")
            try:
                fv = float(v)
            except (TypeError, ValueError):
                raise ModelError(f'parameter "{k}": value must be a number, got {v!r}') from None
            if not math.isfinite(fv):
                raise ModelError(f'parameter "{k}": value {v!r} is not finite')
            why = magnitude_problem(fv)
            if why:
                raise ModelError(f'parameter "{k}": {why}')
            pvals.append((k, fv))
        set_(self, "parameters", tuple(pvals))
        set_(self, "units", tuple((str(k), str(v)) for k, v in (units or {}).items()))
        for b in body_list:
            if not isinstance(b, Body):
                raise ModelError(f"bodies: expected Body objects, got {type(b).__name__} {b!r}")
        forces, frictions = split_frictions(force_list)
        for f in forces:
            if not isinstance(f, Gravity | Force | Torque | SpringDamper | GeneralizedForce
                              | Bushing):
                raise ModelError(f"forces: expected force elements, got {type(f).__name__} {f!r}")
        set_(self, "bodies", parents_first(body_list))  # type: ignore[arg-type]
        set_(self, "forces", tuple(forces))
        set_(self, "quantities", tuple(quantities_in(
            [e for f in forces for e in force_expressions(f)]).values()))
        validate(self)
        set_(self, "closing", _closing_joints(self, closing))
        set_(self, "contacts", _contacts(self, contacts))
        set_(self, "independent", _independent(self, independent))
        set_(self, "speeds", _speeds(self, speeds))
        set_(self, "frictions", check_frictions(self, frictions))
        set_(self, "groups", groups)

    def __hash__(self) -> int:
        """The hash of the fields, computed once: the memoized stages (``mkq_function(system)``
        and the like) look a system up on every call, and hashing its bodies and expressions
        anew took 10 µs each time. The fields never change (frozen), so neither does the hash;
        equality stays the dataclass's field-by-field comparison."""
        h = self.__dict__.get("_hash")
        if h is None:
            h = hash(tuple(getattr(self, f.name) for f in fields(self)))
            object.__setattr__(self, "_hash", h)
        return h

    def __getstate__(self) -> dict:
        # what is kept under private names (the cached hash; a subclass's kept stages and its
        # lock) belongs to this process (hashes of expressions differ between processes): a
        # copy sent to another one computes its own
        return {k: v for k, v in self.__dict__.items() if not k.startswith("_")}

    def __setstate__(self, state: dict) -> None:
        for k, v in state.items():
            object.__setattr__(self, k, v)

    # --- the tree and its closing joints --------------------------------------------------------
    @property
    def is_closed(self) -> bool:
        """True when closing joints close kinematic loops of the tree, or contacts constrain
        it (every tree-only path refuses it)."""
        return bool(self.closing) or self.is_general

    @property
    def is_general(self) -> bool:
        """True for a *general* system (METHOD.md §7): velocity constraints (contacts), or
        generalized velocities z other than ẏ."""
        return bool(self.contacts) or self.speeds is not None

    @property
    def tree(self) -> Self:
        """The open tree: the same bodies, joints, forces and parameters without the closing
        joints (the system itself when it has none), of the same class."""
        if not self.closing and not self.is_general:
            return self
        tree = self.__dict__.get("_tree")
        if tree is None:
            tree = type(self)(self.coordinates, self.bodies, self.forces,
                              dict(self.parameters), self.inputs, dict(self.units), self.name)
            object.__setattr__(tree, "groups", self.groups)
            object.__setattr__(self, "_tree", tree)
        return tree

    def closed_by(self, closing: Sequence[ClosingJoint], independent: Sequence[str] | None = None,
                  name: str | None = None) -> Self:
        """This tree closed by the ``closing`` joints (a new system of the same class), with
        the ``independent`` coordinates chosen (else by the partition at the initial
        configuration)."""
        closed = type(self)(self.coordinates, self.bodies, (*self.forces, *self.frictions),
                            dict(self.parameters), self.inputs, dict(self.units),
                            self.name if name is None else name,
                            closing=(*self.closing, *closing), independent=independent,
                            contacts=self.contacts, speeds=_speed_arg(self.speeds))
        object.__setattr__(closed, "groups", self.groups)
        return closed

    def grubler(self) -> int:
        """Degrees of freedom by the Grübler–Kutzbach count (spatial: 6 per body), the tree's
        joints and the closing joints counted."""
        return grubler(len(self.bodies), [len(b.joint.coordinates) for b in self.bodies],
                       self.closing)

    # --- names and symbols -------------------------------------------------------------------
    @property
    def y(self) -> tuple[se.Symbol, ...]:
        """Generalized coordinates y."""
        return self.coordinates

    @property
    def yd(self) -> tuple[se.Symbol, ...]:
        """Symbols of the rates ẏ (``<name>_d``)."""
        return tuple(rate(c) for c in self.coordinates)

    @property
    def ydd(self) -> tuple[se.Symbol, ...]:
        """Symbols of the accelerations ÿ (``<name>_dd``)."""
        return tuple(acceleration(c) for c in self.coordinates)

    @property
    def t(self) -> se.Symbol:
        return t

    @property
    def f(self) -> int:
        """Number of degrees of freedom."""
        return len(self.coordinates)

    @property
    def coordinate_names(self) -> list[str]:
        return [str(c) for c in self.coordinates]

    @property
    def input_names(self) -> list[str]:
        return [str(c) for c in self.inputs]

    @property
    def parameter_values(self) -> dict[str, float]:
        """Default numeric values of the parameters (a fresh dict)."""
        return dict(self.parameters)

    @property
    def parameter_symbols(self) -> tuple[se.Symbol, ...]:
        return tuple(se.Symbol(k) for k, _ in self.parameters)

    @property
    def body_names(self) -> list[str]:
        return [b.name for b in self.bodies]

    def body(self, name: str) -> Body:
        """The body called ``name`` (ModelError if there is none)."""
        for b in self.bodies:
            if b.name == name:
                return b
        raise ModelError(f'unknown body "{name}"; bodies are: {", ".join(self.body_names)}')

    def __repr__(self) -> str:
        closing = (f", closing joints {[c.name for c in self.closing]}" if self.closing
                   else "")
        if self.contacts:
            closing += f", contacts {[c.name for c in self.contacts]}"
        return (f"System({self.name!r}: {len(self.bodies)} bodies{closing}, f={self.f}, "
                f"coordinates={self.coordinate_names}, parameters={list(dict(self.parameters))}, "
                f"inputs={self.input_names})")


def _closing_joints(system: System, closing: Sequence[ClosingJoint]) -> tuple[ClosingJoint, ...]:
    """The closing joints, checked against the tree: names unique among all joints, bodies
    known, symbols only parameters (and, for general constraints, coordinates and t)."""
    closing = tuple(closing)
    names: set[str] = set()
    bodies = set(system.body_names) | {"world"}
    joint_names = {b.joint.name for b in system.bodies}
    params = {k for k, _ in system.parameters}
    coords = set(system.coordinate_names)
    for cj in closing:
        if not isinstance(cj, ClosingJoint):
            raise ModelError(f"closing joints: expected ClosingJoint objects, got "
                             f"{type(cj).__name__}")
        if cj.name in names or cj.name in joint_names:
            raise ModelError(f'closing joint "{cj.name}": the name is used twice')
        names.add(cj.name)
        for side in (cj.body_a, cj.body_b):
            if side not in bodies:
                raise ModelError(f'closing joint "{cj.name}": unknown body "{side}"; bodies '
                                 f"are {', '.join(sorted(bodies))}")
        allowed = params | (coords | {"t"} if cj.type == "constraint" else set())
        unknown = sorted(cj.symbols() - allowed)
        if unknown:
            what = ("coordinates, t and parameters" if cj.type == "constraint"
                    else "parameters (points and axes are constant in their bodies)")
            raise ModelError(f'closing joint "{cj.name}": unknown name(s) '
                             f"{', '.join(unknown)}; it may use {what}")
    return closing


def _independent(system: System, independent: Sequence[str] | None) -> tuple[str, ...] | None:
    if independent is None:
        return None
    if not system.closing and not system.contacts:
        raise ModelError("independent coordinates are chosen for closed systems only (this "
                         "one has no closing joints or contacts)")
    ind = tuple(str(c) for c in independent)
    for c in ind:
        if c not in system.coordinate_names:
            raise ModelError(f'independent coordinate "{c}" is not a coordinate of the tree '
                             f"({', '.join(system.coordinate_names)})")
    if len(set(ind)) != len(ind):
        raise ModelError(f"independent coordinates {list(ind)} name one twice")
    return ind


def _contacts(system: System, contacts: Sequence[Contact]) -> tuple[Contact, ...]:
    """The velocity constraints, checked: names unique among joints, closing joints and
    contacts, bodies known, general rows linear in the rates."""
    contacts = tuple(contacts)
    taken = {b.joint.name for b in system.bodies} | {c.name for c in system.closing}
    bodies = set(system.body_names)
    for c in contacts:
        if not isinstance(c, CONTACT_TYPES):
            raise ModelError(f"contacts: expected RollingDisc, KnifeEdge or VelocityConstraint "
                             f"objects, got {type(c).__name__} {c!r}")
        if c.name in taken:
            raise ModelError(f'contact "{c.name}": the name is used twice')
        taken.add(c.name)
        for b in c.bodies:
            if b not in bodies:
                raise ModelError(f'contact "{c.name}": unknown body "{b}"; bodies are '
                                 f"{', '.join(system.body_names)}")
        if hasattr(c, "expressions"):
            check_linear(c.name, c.expressions, system.coordinates)
            allowed = set(system.coordinate_names) | {f"{n}_d" for n in system.coordinate_names}
        else:
            allowed = set()
        allowed |= set(dict(system.parameters)) | {"t"}
        unknown = sorted(c.symbols() - allowed)
        if unknown:
            raise ModelError(f'contact "{c.name}": unknown name(s) ' + ", ".join(unknown))
    return contacts


def _speeds(system: System, speeds: Sequence[str] | Mapping[str, object] | None
            ) -> tuple[tuple[str, se.Basic], ...] | None:
    """The generalized velocities as (name, definition linear in ẏ): a coordinate's name gives
    ``<name>_d`` defined as its rate."""
    if speeds is None:
        return None
    names = system.coordinate_names
    out: list[tuple[str, se.Basic]] = []
    if isinstance(speeds, Mapping):
        for k, v in speeds.items():
            name = str(k)
            if not name.isidentifier():
                raise ModelError(f"speeds: name {name!r} must be an identifier")
            e = as_expr(v, f'speed "{name}"')
            check_linear(f"speed {name}", [e], system.coordinates)
            out.append((name, e))
    else:
        if isinstance(speeds, str):
            speeds = [s.strip() for s in speeds.replace(",", " ").split()]
        for c in speeds:
            if str(c) not in names:
                raise ModelError(f'speeds: "{c}" is not a coordinate ({", ".join(names)}); '
                                 "give definitions as a mapping name -> expression")
            out.append((f"{c}_d", rate(system.coordinates[names.index(str(c))])))
    if len({n for n, _ in out}) != len(out):
        raise ModelError(f"speeds {[n for n, _ in out]} name one twice")
    return tuple(out)


def _speed_arg(speeds: tuple[tuple[str, se.Basic], ...] | None) -> dict[str, se.Basic] | None:
    return None if speeds is None else dict(speeds)
