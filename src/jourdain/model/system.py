"""The immutable, validated model: coordinates, parameters, inputs, bodies and force elements.

Pure data: the stages of the method take a System (:mod:`jourdain.stages`), and
:class:`jourdain.System` (:mod:`jourdain.pipeline`) adds them as cached methods; nothing here
imports them (docs/architecture.md)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields

import symengine as se

from ..errors import ModelError
from .bodies import Body
from .expressions import as_expr, t
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
        set_(self, "bodies", parents_first(bodies))
        set_(self, "forces", tuple(forces))
        set_(self, "quantities", tuple(quantities_in(
            [e for f in forces for e in force_expressions(f)]).values()))
        validate(self)

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
        return (f"System({self.name!r}: {len(self.bodies)} bodies, f={self.f}, "
                f"coordinates={self.coordinate_names}, parameters={list(dict(self.parameters))}, "
                f"inputs={self.input_names})")
