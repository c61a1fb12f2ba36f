"""The immutable, validated model: coordinates, parameters, inputs, bodies and force elements."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import ModelError
from .bodies import WORLD, Body, check_values
from .expressions import as_expr, free_names, t, values_at
from .forces import (
    RESERVED,
    Bushing,
    Force,
    ForceElement,
    GeneralizedForce,
    Gravity,
    SpringDamper,
    Torque,
    acceleration,
    deflection,
    deflection_d,
    elongation,
    elongation_d,
    rate,
)
from .joints import orientation_problem
from .quantities import Quantity, quantities_in

if TYPE_CHECKING:
    from ..stages.kinematics import Kinematics
    from ..stages.linearization import Linearization
    from ..stages.newton_euler import NewtonEuler
    from ..stages.projection import EquationsOfMotion
    from ..stages.reactions import Reactions


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
    bodies : sequence of Body
        Each hangs from ``"world"`` or from another body through its joint. The order is kept:
        it is the order of :attr:`bodies`, of the body rows of M̄, J̄, q̄^c, q̄^e and of the
        joints in the reactions g. Every parent must come before its children (any such order
        is valid for the method); a child listed before its parent raises a ModelError naming
        both and their positions.
    forces : sequence of force elements
        Gravity, Force, Torque, SpringDamper, GeneralizedForce (RotationalSpringDamper),
        Bushing. Their laws may use kinematic quantities
        (:mod:`jourdain.model.quantities`), found from their symbols: :attr:`quantities`.
    parameters : mapping name -> default value
        Every symbol in the model other than coordinates, rates, inputs and ``t``.
    inputs : sequence of symbols or names
        Input symbols ``u`` (actuator forces, excitations), given as functions of time when
        simulating.
    units : mapping name -> unit string, optional
        Units of parameters and coordinates, for reports.
    name : str
    """

    coordinates: tuple[se.Symbol, ...]
    bodies: tuple[Body, ...]
    forces: tuple[ForceElement, ...]
    parameters: tuple[tuple[str, float], ...]
    inputs: tuple[se.Symbol, ...]
    units: tuple[tuple[str, str], ...]
    name: str
    quantities: tuple[Quantity, ...]

    def __init__(self, coordinates: Sequence[object] | str, bodies: Sequence[Body],
                 forces: Sequence[ForceElement] = (), parameters: Mapping[str, float] | None = None,
                 inputs: Sequence[object] | str = (), units: Mapping[str, str] | None = None,
                 name: str = "system") -> None:
        y = _symbol_list(coordinates, "coordinates")
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
            pvals.append((k, fv))
        set_(self, "parameters", tuple(pvals))
        set_(self, "units", tuple((str(k), str(v)) for k, v in (units or {}).items()))
        bodies = list(bodies)
        for b in bodies:
            if not isinstance(b, Body):
                raise ModelError(f"bodies: expected Body objects, got {type(b).__name__} {b!r}")
        forces = list(forces)
        for f in forces:
            if not isinstance(f, Gravity | Force | Torque | SpringDamper | GeneralizedForce
                              | Bushing):
                raise ModelError(f"forces: expected force elements, got {type(f).__name__} {f!r}")
        set_(self, "bodies", _parents_first(bodies))
        set_(self, "forces", tuple(forces))
        set_(self, "quantities", tuple(quantities_in(
            [e for f in forces for e in _force_expressions(f)]).values()))
        _validate(self)

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
        # the cached hash belongs to this process (hashes of expressions differ between
        # processes): a copy sent to another one computes its own
        return {k: v for k, v in self.__dict__.items() if k != "_hash"}

    def __setstate__(self, state: dict) -> None:
        for k, v in state.items():
            object.__setattr__(self, k, v)

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

    # --- the stages, for convenience -------------------------------------------------------
    def kinematics(self) -> Kinematics:
        """Kinematics of every body (METHOD §1); see :func:`jourdain.stages.kinematics.kinematics`."""
        from ..stages.kinematics import kinematics

        return kinematics(self)

    def newton_euler(self) -> NewtonEuler:
        """Newton–Euler equations M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g (METHOD §2)."""
        from ..stages.newton_euler import newton_euler

        return newton_euler(self.kinematics())

    def equations_of_motion(self) -> EquationsOfMotion:
        """Equations of motion M·ÿ + k = q by projection with J̄ᵀ (METHOD §3)."""
        from ..stages.projection import projection

        return projection(self.newton_euler())

    def reactions(self) -> Reactions:
        """Reaction forces: Q̄ from the joints, N̂·g = k̂ − q̂ (METHOD §4)."""
        from ..stages.reactions import reactions

        return reactions(self.newton_euler())

    def linearize(self, nominal: Mapping[Any, Any] | Any,
                  inputs: Mapping[Any, Any] | None = None) -> Linearization:
        """Linearization M̃·η̈ + P·η̇ + Q·η = h + B·Δu about a nominal motion (METHOD §5), with
        nominal ``inputs`` ``{input: u_s}`` where given (zero otherwise); see
        :func:`jourdain.stages.linearization.linearization`."""
        from ..stages.linearization import linearization

        return linearization(self.equations_of_motion(), nominal, inputs)

    def evaluate(self, y: Any, yd: Any, t: float = 0.0, parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, float] | Sequence[float] | None = None) -> dict[str, np.ndarray]:
        """Numbers at one state: a dict from the seed's names to NumPy arrays.

        Keys: ``M_bar, J_bar, q_c, q_e, M, k, q``, and the reactions ``Q_bar, N_hat, k_hat,
        q_hat, g, g_names, g_undetermined`` (:func:`jourdain.stages.reactions.evaluate_reactions`;
        only ``reactions_error`` where the model's reactions cannot be formed).
        ``parameters`` overrides default values by name; ``inputs`` gives the inputs by name (or
        in the order of :attr:`input_names`).
        """
        from ..numeric import evaluate
        from ..stages.reactions import evaluate_keys

        out = evaluate(self, y, yd, t=t, parameters=parameters, inputs=inputs)
        out.update(evaluate_keys(self, y, yd, t, parameters, inputs, eom=out))
        return out

    def simulate(self, t_span: tuple[float, float], y0: Any, yd0: Any,
                 parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, Any] | None = None, method: str | None = None,
                 rtol: float | None = None, atol: Any = None, t_eval: Any = None,
                 **options: Any) -> Any:
        """Integrate the equations of motion from ``y0, ẏ0`` over ``t_span``; returns a
        :class:`jourdain.simulation.results.Results` (see :func:`jourdain.simulation.simulate.simulate` for the
        methods, inputs, events and options). ``method``, ``rtol``, ``atol`` left out: the
        defaults of :mod:`jourdain.simulation.simulate` (DOP853, 1e-8, 1e-10), the same as model files'."""
        from ..simulation.simulate import DEFAULT_ATOL, DEFAULT_METHOD, DEFAULT_RTOL, simulate

        return simulate(self, t_span, y0, yd0, parameters=parameters, inputs=inputs,
                        method=DEFAULT_METHOD if method is None else method,
                        rtol=DEFAULT_RTOL if rtol is None else rtol,
                        atol=DEFAULT_ATOL if atol is None else atol, t_eval=t_eval, **options)

    def __repr__(self) -> str:
        return (f"System({self.name!r}: {len(self.bodies)} bodies, f={self.f}, "
                f"coordinates={self.coordinate_names}, parameters={list(dict(self.parameters))}, "
                f"inputs={self.input_names})")


def _parents_first(bodies: list[Body]) -> tuple[Body, ...]:
    """The bodies in the order given, checked to list every parent before its children.

    The rows of M̄, J̄, q̄^c, q̄^e and the joints of g follow this order. Any order with parents
    first is valid for the method, so the user's is kept; one with a child before its parent is
    refused instead of being rearranged behind the user's back.
    """
    position: dict[str, int] = {}
    for k, b in enumerate(bodies):
        if b.name in position:
            raise ModelError(f'duplicate body name "{b.name}"')
        position[b.name] = k
    for b in bodies:
        if b.parent != WORLD and b.parent not in position:
            raise ModelError(
                f'body "{b.name}": unknown parent "{b.parent}" (not a body and not "world")'
            )
    # with every parent listed first the parents cannot form a cycle; where one is listed
    # later, a cycle is reported as such rather than as a matter of order
    parent = {b.name: b.parent for b in bodies}
    for k, b in enumerate(bodies):
        if b.parent == WORLD or position[b.parent] < k:
            continue
        chain = [b.name]
        while parent[chain[-1]] != WORLD and parent[chain[-1]] not in chain:
            chain.append(parent[chain[-1]])
        if parent[chain[-1]] != WORLD:
            cycle = " → ".join([*chain[chain.index(parent[chain[-1]]):], parent[chain[-1]]])
            raise ModelError(
                f'body "{b.name}" is not connected to the inertial frame (a cycle of parents: '
                f'{cycle}); every chain of parents must end at "{WORLD}"'
            )
        raise ModelError(
            f'body "{b.name}" (position {k + 1}) comes before its parent "{b.parent}" '
            f"(position {position[b.parent] + 1}): list parents before their children"
        )
    return tuple(bodies)


def _validate(sys: System) -> None:
    y_names = [str(c) for c in sys.coordinates]
    u_names = [str(c) for c in sys.inputs]
    p_names = [k for k, _ in sys.parameters]
    rate_names = [f"{n}_d" for n in y_names] + [f"{n}_dd" for n in y_names]
    if not y_names:
        raise ModelError("a system needs at least one generalized coordinate")
    if not sys.bodies:
        raise ModelError("a system needs at least one body")
    seen: dict[str, str] = {}
    for kind, names in (("coordinate", y_names), ("input", u_names), ("parameter", p_names),
                        ("coordinate rate", rate_names)):
        for n in names:
            if n in RESERVED:
                raise ModelError(f'{kind} name "{n}" is reserved')
            if n in seen:
                raise ModelError(f'name "{n}" is declared twice (as {seen[n]} and as {kind})')
            seen[n] = kind

    joint_names: dict[str, str] = {}
    driven_by: dict[str, str] = {}
    used_coords: set[str] = set()
    allowed_kin = set(y_names) | set(p_names) | {"t"}
    defaults = dict(sys.parameters)
    for b in sys.bodies:
        j = b.joint
        if j.name in joint_names:
            raise ModelError(
                f'duplicate joint name "{j.name}" (bodies "{joint_names[j.name]}" and "{b.name}")'
            )
        joint_names[j.name] = b.name
        for c in j.coordinates:
            cn = str(c)
            if cn not in y_names:
                raise ModelError(f'joint "{j.name}" (body "{b.name}"): "{cn}" is not a declared coordinate')
            if cn in driven_by:
                raise ModelError(
                    f'coordinate "{cn}" is driven by two joints: "{driven_by[cn]}" and "{j.name}"'
                )
            driven_by[cn] = j.name
        exprs = [*j.position, *(x for row in j.orientation for x in row)]
        for s in j.steps:
            exprs.extend([s.angle] if hasattr(s, "angle") else list(s.vector))
        names = free_names(exprs)
        bad = names - allowed_kin
        if bad:
            raise ModelError(
                f'joint "{j.name}" (body "{b.name}"): undeclared symbol(s) {sorted(bad)}; joints may '
                "depend on coordinates, parameters and t only"
            )
        used_coords |= names & set(y_names)
        _check_axes(sys, b)
        # mass data
        mass_names = free_names([b.mass, *b.com, *(x for row in b.inertia for x in row)])
        bad = mass_names - set(p_names)
        if bad:
            raise ModelError(f'body "{b.name}": mass data use undeclared symbol(s) {sorted(bad)}')
        # mass data a rigid body can have, and joint frames and axes, at the default values
        check_values([b], defaults)
    unused = [n for n in y_names if n not in used_coords]
    if unused:
        raise ModelError(f"coordinate(s) {unused} are not used by any joint")

    body_names = {b.name for b in sys.bodies}
    allowed_force = set(y_names) | set(p_names) | set(u_names) | {"t"} | {f"{n}_d" for n in y_names}
    q_names = _check_quantities(sys, seen, body_names, set(p_names))
    allowed_force |= q_names
    force_names: set[str] = set()
    for f in sys.forces:
        w = f'force "{f.name}"'
        if f.name in force_names:
            raise ModelError(f'duplicate force name "{f.name}"')
        force_names.add(f.name)
        exprs: list = []
        extra: set[str] = set()
        if isinstance(f, Gravity):
            exprs = list(f.vector)
        elif isinstance(f, Force | Torque):
            if f.body not in body_names:
                raise ModelError(f'{w}: unknown body "{f.body}"')
            if f.frame != WORLD and f.frame not in body_names:
                raise ModelError(f'{w}: unknown frame "{f.frame}" (a body name or "world")')
            exprs = list(f.vector) + list(getattr(f, "point", ()))
        elif isinstance(f, SpringDamper):
            for bn in (f.body_a, f.body_b):
                if bn != WORLD and bn not in body_names:
                    raise ModelError(f'spring-damper "{f.name}": unknown body "{bn}"')
            if f.body_a == f.body_b:
                raise ModelError(f'spring-damper "{f.name}": both ends are on body "{f.body_a}"')
            exprs = [*f.point_a, *f.point_b, f.stiffness, f.damping, f.rest_length]
            if f.law is not None:
                exprs.append(f.law)
                extra = {str(elongation), str(elongation_d)}
        elif isinstance(f, GeneralizedForce):
            if f.on_coordinate:
                if str(f.coordinate) not in y_names:
                    raise ModelError(f'{w}: "{f.coordinate}" is not a declared coordinate')
            else:
                used = free_names([f.coordinate])
                bad = used - (set(y_names) | set(p_names) | {"t"} | q_names)
                if bad:
                    raise ModelError(f"{w}: its coordinate {f.coordinate} uses {sorted(bad)}; "
                                     "it may use coordinates, parameters, t and kinematic "
                                     "quantities of positions")
                if not used & set(y_names) and not used & q_names:
                    raise ModelError(f"{w}: its coordinate {f.coordinate} depends on no "
                                     "coordinate")
            exprs = [f.value]
            extra = {str(deflection), str(deflection_d)}
        elif isinstance(f, Bushing):
            w = f'bushing "{f.name}"'
            for bn in (f.body_a, f.body_b):
                if bn != WORLD and bn not in body_names:
                    raise ModelError(f'{w}: unknown body "{bn}"')
            if f.body_a == f.body_b:
                raise ModelError(f'{w}: both ends are on body "{f.body_a}"')
            points = free_names([*f.point_a, *f.point_b]) - set(p_names)
            if points:
                raise ModelError(f"{w}: points use {sorted(points)}; points may use parameters "
                                 "only")
            for key in ("axes_a", "axes_b"):
                R = getattr(f, key)
                bad = free_names([x for row in R for x in row]) - set(p_names)
                if bad:
                    raise ModelError(f"{w}: {key} uses {sorted(bad)}; axes may use parameters "
                                     "only")
                why = orientation_problem(R, defaults)
                if why:
                    raise ModelError(f"{w}: {key}: the matrix {why}")
            exprs = f.expressions
            extra = {str(deflection), str(deflection_d)}
        bad = free_names(exprs) - allowed_force - extra
        if bad:
            hint = ""
            if isinstance(f, GeneralizedForce | Bushing) and bad & {str(elongation),
                                                                  str(elongation_d)}:
                hint = " (use deflection and deflection_d here)"
            raise ModelError(f"{w}: undeclared symbol(s) {sorted(bad)}{hint}")


def _force_expressions(f: object) -> list:
    """Every expression of a force element (to find the kinematic quantities it uses)."""
    if isinstance(f, Gravity):
        return list(f.vector)
    if isinstance(f, Force):
        return [*f.vector, *f.point]
    if isinstance(f, Torque):
        return list(f.vector)
    if isinstance(f, SpringDamper):
        return [f.stiffness, f.damping, f.rest_length, *([f.law] if f.law is not None else [])]
    if isinstance(f, GeneralizedForce):
        return [f.coordinate, f.value]
    if isinstance(f, Bushing):
        return f.expressions
    return []


def _check_quantities(sys: System, seen: dict[str, str], body_names: set[str],
                      p_names: set[str]) -> set[str]:
    """Check the kinematic quantities the forces use; return the names of their symbols."""
    names: set[str] = set()
    for q in sys.quantities:
        w = f'quantity "{q.name}" ({q.kind})'
        for bn in q.bodies:
            if bn != WORLD and bn not in body_names:
                raise ModelError(f'{w}: unknown body or frame "{bn}" (a body name or "world")')
        bad = free_names(list(q.expressions)) - p_names
        if bad:
            raise ModelError(f"{w}: points use {sorted(bad)}; points may use parameters only")
        for n in q.symbol_names:
            if n in seen or n in RESERVED:
                what = seen.get(n, "a reserved name")
                raise ModelError(f'{w}: its symbol "{n}" is already declared (as {what})')
            names.add(n)
    # a generalized force's coordinate must not depend on rates through a quantity
    for f in sys.forces:
        if isinstance(f, GeneralizedForce) and not f.on_coordinate:
            for s in f.coordinate.free_symbols:
                q = getattr(s, "quantity", None)
                if q is not None and q.uses_rates:
                    raise ModelError(
                        f'force "{f.name}": its coordinate uses {q.describe()}, which depends '
                        "on the rates; a generalized coordinate may use positions, relative "
                        "positions and distances only")
    return names


def _check_axes(sys: System, b: Body) -> None:
    """Axes of the joint's steps: constant in the frame before the step (parameters only, as
    the kinematics takes u̇ = 0) and, for axes with parameters, not zero at the default values
    (:func:`jourdain.model.expressions.unit_axis` divides them by their symbolic length)."""
    j = b.joint
    p_names = {k for k, _ in sys.parameters}
    defaults = dict(sys.parameters)
    for k, step in enumerate(j.steps):
        u = step.axis
        names = free_names(u) if u is not None else set()
        if not names:
            continue
        axis = "the axis" if len({s.axis for s in j.steps}) == 1 else f"the axis of step {k}"
        where = f'joint "{j.name}" (body "{b.name}"): {axis}'
        bad = names - p_names
        if bad:
            raise ModelError(f"{where} uses {sorted(bad)}; axes may depend on parameters only")
        if not all(math.isfinite(v) for v in values_at(u, defaults)):  # NaN: no real value
            raise ModelError(f"{where} is the zero vector at the default parameter values")


