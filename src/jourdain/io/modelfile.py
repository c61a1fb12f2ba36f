"""Model files: a multibody system, its nominal motions and simulation settings in TOML.

The format is described in ``docs/model-format.md``. :func:`load_model` reads a file,
:func:`loads_model` a string. Expressions are read by :mod:`jourdain.io.expressions` (never by
Python); every mistake raises :class:`ModelFileError` naming the file, the line and the key path::

    double.toml:14: body "rod2" → joint → axis: expected one of x, y, z or a 3-vector, got "w"
"""

from __future__ import annotations

import difflib
import math
import os
import re
import tomllib
from collections.abc import Callable, Container, Mapping
from dataclasses import dataclass, field
from pathlib import Path as FsPath
from typing import Any

import symengine as se

from ..errors import JourdainError, ModelError
from ..model import (
    WORLD,
    Body,
    Bushing,
    Cylindrical,
    Fixed,
    Force,
    Free,
    General,
    GeneralizedForce,
    Gravity,
    Planar,
    Prismatic,
    Revolute,
    Rot,
    RotationalSpringDamper,
    Spherical,
    SpringDamper,
    System,
    Torque,
    Trans,
    Universal,
    box,
    cylinder,
    disc,
    rod,
)
from ..model.bodies import mass_data_problem
from ..model.expressions import unit_axis
from ..model.forces import BUSHING_COMPONENTS
from ..model.joints import orientation_problem
from ..model.quantities import KINDS as QUANTITY_KINDS
from ..model.quantities import declare as declare_quantity
from ..model.quantities import quantity as make_quantity
from ..simulation.simulate import (
    DEFAULT_ATOL,
    DEFAULT_METHOD,
    DEFAULT_RTOL,
    DEFAULT_SAMPLES,
    DEFAULT_T_END,
    check_atol,
    check_rtol,
    check_samples,
    check_t_end,
)
from .expressions import RESERVED_NAMES, ExpressionError, _number, parse_expression
from .toml_positions import Path, deep_nesting, key_lines, line_of

__all__ = ["MAX_FILE_BYTES", "ModelFile", "ModelFileError", "NominalMotion",
           "SimulationSettings", "load_model", "loads_model"]

#: Largest model file read (bytes). Real models are a few kB to a few hundred kB; reading and
#: locating the keys of a file takes about a second per MB, so larger files are refused at once.
MAX_FILE_BYTES = 4_000_000
#: Deepest nesting of arrays and inline tables reported by name when the TOML reader gives up
#: (model files nest three or four levels).
_MAX_NESTING = 32


class ModelFileError(ModelError):
    """A mistake in a model file. ``file``, ``line`` and ``path`` (the key path) say where."""

    def __init__(self, message: str, file: str, line: int | None, path: Path = (),
                 detail: str = "") -> None:
        super().__init__(message)
        self.file = file
        self.line = line
        self.path = path
        self.detail = detail


@dataclass(frozen=True)
class NominalMotion:
    """A nominal motion y_s(t) to linearize about (METHOD §5).

    ``y``, ``yd``, ``ydd`` are tuples (one entry per coordinate, in the system's order) of
    expressions in ``t`` and the parameters; ``yd`` and ``ydd`` are the time derivatives of ``y``
    unless the file gives the rates explicitly. ``inputs`` holds the nominal inputs ``u_s`` as
    ``(name, expression)`` pairs (inputs not given are 0).
    """

    name: str
    y: tuple[se.Basic, ...]
    yd: tuple[se.Basic, ...]
    ydd: tuple[se.Basic, ...]
    description: str = ""
    inputs: tuple[tuple[str, se.Basic], ...] = ()
    #: the period T of a periodic nominal motion (an expression in the parameters; None
    #: otherwise): the report and ``jourdain linearize`` then give its Floquet analysis
    period: se.Basic | None = None

    @property
    def is_equilibrium(self) -> bool:
        """True when y_s is constant (no ``t``) and all rates vanish."""
        t = se.Symbol("t")
        return all(t not in e.free_symbols for e in self.y) and all(e == 0 for e in self.yd)


@dataclass(frozen=True)
class SimulationSettings:
    """How ``jourdain simulate`` integrates the equations of motion.

    ``y0`` and ``yd0`` are the initial coordinates and rates (system order); ``inputs`` maps each
    input name to an expression in ``t`` and the parameters (0 when not given).
    """

    t_end: float = DEFAULT_T_END
    samples: int = DEFAULT_SAMPLES
    method: str = DEFAULT_METHOD
    rtol: float = DEFAULT_RTOL
    atol: float = DEFAULT_ATOL
    y0: tuple[float, ...] = ()
    yd0: tuple[float, ...] = ()
    inputs: tuple[tuple[str, se.Basic], ...] = ()


@dataclass(frozen=True)
class ModelFile:
    """A loaded model file: the :class:`~jourdain.System` and what else the file describes."""

    path: str
    system: System
    description: str = ""
    nominal: tuple[NominalMotion, ...] = ()
    simulation: SimulationSettings = field(default_factory=SimulationSettings)
    descriptions: tuple[tuple[str, str], ...] = ()
    view: str | None = None
    #: the :class:`jourdain.loops.ClosedLoopSystem` of ``[closing_joints.<name>]`` (else None)
    loops: Any = None

    def error(self, message: str) -> ModelFileError:
        """A :class:`ModelFileError` for a problem a later stage found in this model (e.g. a
        joint whose constrained directions violate J̄ᵀQ̄ = 0), located in the file by the body,
        joint or force that the message names."""
        try:
            with open(self.path, "rb") as fh:
                text = fh.read(MAX_FILE_BYTES + 1).decode("utf-8")
        except (OSError, UnicodeDecodeError):
            text = ""
        loader = _Loader(text if len(text) <= MAX_FILE_BYTES else "", self.path)
        loader.body_names = self.system.body_names
        loader.joint_of_body = {b.name: b.joint.name for b in self.system.bodies}
        path = loader.locate(message)
        if path[:1] == ("bodies",) and len(path) == 3 and (*path, "constrained") in loader.lines:
            path = (*path, "constrained")
        return loader.fail(path, message)

    def nominal_motion(self, name: str | None = None) -> NominalMotion:
        """The nominal motion called ``name`` (the first one when ``None``)."""
        if not self.nominal:
            raise ModelError(f"{self.path}: the model defines no nominal motion ([nominal.<name>])")
        if name is None:
            return self.nominal[0]
        for n in self.nominal:
            if n.name == name:
                return n
        names = ", ".join(n.name for n in self.nominal)
        raise ModelError(f'{self.path}: no nominal motion "{name}"; the model has: {names}')


# ------------------------------------------------------------------------------------------
# schema
# ------------------------------------------------------------------------------------------

_TOP = {"model", "coordinates", "parameters", "inputs", "bodies", "forces", "nominal",
        "simulation", "quantities", "closing_joints", "loops"}
_JOINT_KEYS: dict[str, set[str]] = {
    "revolute": {"coordinate", "axis"},
    "prismatic": {"coordinate", "axis"},
    "cylindrical": {"coordinates", "axis"},
    "universal": {"coordinates", "axes"},
    "spherical": {"coordinates", "sequence"},
    "planar": {"coordinates", "normal"},
    "free": {"coordinates", "sequence"},
    "fixed": set(),
    "general": {"steps", "coordinates", "constrained"},
}
_JOINT_COMMON = {"type", "name", "position", "orientation"}
_FORCE_KEYS: dict[str, set[str]] = {
    "gravity": {"vector"},
    "force": {"body", "vector", "point", "frame"},
    "torque": {"body", "vector", "frame"},
    "spring_damper": {"body_a", "point_a", "body_b", "point_b", "stiffness", "damping",
                      "rest_length", "law"},
    "generalized": {"coordinate", "value"},
    "rotational_spring_damper": {"coordinate", "stiffness", "damping", "rest_angle"},
    "bushing": {"body_a", "point_a", "body_b", "point_b", "frame", "stiffness", "damping",
                "preload", "laws", "axes_a", "axes_b"},
}
#: keys of a [quantities.<name>] table, by its type (one point, or two points)
_QUANTITY_KEYS_ONE = {"body", "point", "frame", "point_frame"}
_QUANTITY_KEYS_TWO = {"body_a", "point_a", "body_b", "point_b", "frame"}
_SHAPES = {"point": set(), "rod": {"length", "axis"}, "disc": {"radius", "axis"},
           "cylinder": {"radius", "length", "axis"}, "box": {"a", "b", "c"}}
_IDENT = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
# line breaks and other control characters (C0, DEL, C1, the Unicode line separators)
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


def _clip(text: str, n: int = 120) -> str:
    """``text`` for a message: at most ``n`` characters, the middle left out."""
    return text if len(text) <= n else f"{text[:n // 2]} … {text[-n // 2:]}"


def _too_big(size: int, text: str | None = None) -> str | None:
    """Why a file of ``size`` bytes (or characters of ``text``) is refused, or None."""
    if text is not None and size <= MAX_FILE_BYTES < 4 * size:
        size = len(text.encode("utf-8", "surrogatepass"))
    if size <= MAX_FILE_BYTES:
        return None
    return (f"the file is too large ({size / 1e6:.1f} MB); model files are at most "
            f"{MAX_FILE_BYTES / 1e6:g} MB")


def _type_name(v: object) -> str:
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, int | float):
        return f"the number {v!r}"
    if isinstance(v, str):
        return f'the string "{v}"'
    if isinstance(v, dict):
        return "a table"
    if isinstance(v, list):
        return f"an array of {len(v)} item{'s' if len(v) != 1 else ''}"
    return type(v).__name__


def describe_path(path: Path) -> str:
    """``("bodies", "link2", "joint", "axis")`` → ``body "link2" → joint → axis``."""
    singular = {"bodies": "body", "forces": "force", "parameters": "parameter",
                "coordinates": "coordinate", "inputs": "input", "nominal": "nominal motion",
                "quantities": "quantity"}
    parts: list[str] = []
    items = list(path)
    if len(items) >= 2 and items[0] in singular and isinstance(items[1], str):
        parts.append(f'{singular[str(items[0])]} "{items[1]}"')
        items = items[2:]
    elif items and isinstance(items[0], str):
        parts.append(f"[{items[0]}]" if items[0] in _TOP else str(items[0]))
        items = items[1:]
    for it in items:
        if isinstance(it, int):
            if parts:
                parts[-1] += f"[{it}]"
            else:
                parts.append(f"[{it}]")
        else:
            parts.append(str(it))
    return " → ".join(parts) if parts else "the file"


# ------------------------------------------------------------------------------------------
# loader
# ------------------------------------------------------------------------------------------

class _Loader:
    def __init__(self, text: str, filename: str) -> None:
        self.file = filename
        self.text = text
        self._lines: dict[Path, int] | None = None
        self.coords: list[str] = []
        self.params: dict[str, float] = {}
        self.inputs: list[str] = []
        self.units: dict[str, str] = {}
        self.descriptions: dict[str, str] = {}
        self.body_names: list[str] = []
        self.joint_of_body: dict[str, str] = {}
        self.driven: dict[str, str] = {}
        #: symbols of the kinematic quantities of [quantities], by name
        self.quantity_symbols: dict[str, se.Basic] = {}

    @property
    def lines(self) -> dict[Path, int]:
        """Line of every key path, scanned on first use: only a file with a mistake needs it."""
        if self._lines is None:
            self._lines = key_lines(self.text)
        return self._lines

    # --- errors ---------------------------------------------------------------------------
    def fail(self, path: Path, message: str) -> ModelFileError:
        line = line_of(self.lines, path)
        where = describe_path(path)
        for k in range(len(path), 0, -1):  # a core message that names the same element
            prefix = describe_path(path[:k]) + ": "
            if message.startswith(prefix):
                message = message[len(prefix):]
                break
        loc = f"{self.file}:{line}" if line else self.file
        return ModelFileError(f"{loc}: {where}: {message}", self.file, line, path, message)

    def missing(self, message: str) -> ModelFileError:
        """A table the file lacks, located at its first line (a file whose table headers
        were swallowed, e.g. by an unterminated multi-line string, still names a line)."""
        return ModelFileError(f"{self.file}:1: the file: {message}", self.file, 1, (), message)

    def suggest(self, word: str, options: list[str]) -> str:
        close = difflib.get_close_matches(word, options, n=1)
        if not close:  # a name in the other case ("G" for "g") is close, however short
            close = [o for o in options if o.lower() == word.lower()][:1]
        return f' (did you mean "{close[0]}"?)' if close else ""

    # --- typed access ---------------------------------------------------------------------
    def table(self, value: object, path: Path, allowed: set[str] | None = None,
              what: str = "a table") -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(path, f"expected {what}, got {_type_name(value)}")
        if allowed is not None:
            for k in value:
                if k not in allowed:
                    opts = sorted(allowed)
                    raise self.fail((*path, k), f'unknown key "{k}"{self.suggest(k, opts)}; '
                                    f"expected one of {', '.join(opts)}")
        return value

    def require(self, tbl: Mapping[str, Any], key: str, path: Path) -> Any:
        if key not in tbl:
            raise self.fail(path, f'missing key "{key}"')
        return tbl[key]

    def string(self, value: object, path: Path) -> str:
        if not isinstance(value, str):
            raise self.fail(path, f"expected a string, got {_type_name(value)}")
        return value

    def line_string(self, value: object, path: Path) -> str:
        """A string of one line: no line breaks or other control characters (a model's name
        and units are written into comments and headers of the output files)."""
        s = self.string(value, path)
        bad = next((c for c in s if _CONTROL.match(c)), None)
        if bad is not None:
            raise self.fail(path, f"expected one line of text, got a string with the control "
                            f"character {bad!r} at position {s.index(bad) + 1}")
        return s

    def number(self, value: object, path: Path, positive: bool = False,
               integer: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(path, f"expected a number, got {_type_name(value)}")
        if integer and not isinstance(value, int):
            raise self.fail(path, f"expected an integer, got {_type_name(value)}")
        if isinstance(value, int):
            self.integer_in_range(value, path)
        if not math.isfinite(value):
            raise self.fail(path, f"expected a finite number, got {value}")
        if positive and value <= 0:
            raise self.fail(path, f"expected a positive number, got {value}")
        return float(value)

    def integer_in_range(self, value: int, path: Path) -> None:
        """An integer of the file must be a floating-point number (|value| < 1.8e308)."""
        try:
            float(value)
        except OverflowError:
            raise self.fail(path, f"the integer of {len(str(abs(value)))} digits is too large for "
                            "a floating-point number (at most about 1.8e308)") from None

    def name(self, value: object, path: Path, what: str) -> str:
        s = self.string(value, path)
        if not _IDENT.match(s):
            raise self.fail(path, f'{what} name "{s}" must start with a letter and contain only '
                            "letters, digits and _")
        return s

    # --- expressions ----------------------------------------------------------------------
    def names_hint(self, allowed: Container[str], context: str) -> Callable[[str], str]:
        def hint(name: str) -> str:
            if name in self.coords and "coordinates" not in context:
                return f" (coordinates are not allowed in {context})"
            if name.endswith("_d") and name[:-2] in self.coords:
                return f" (rates are not allowed in {context})"
            if name == "t":
                return f" (time t is not allowed in {context})"
            if name in self.inputs:
                return f" (inputs are not allowed in {context})"
            if name in ("elongation", "elongation_d"):
                return " (elongation and elongation_d are allowed in a spring law only)"
            if name in ("deflection", "deflection_d"):
                return (" (deflection and deflection_d are allowed in a generalized force's "
                        "value and a bushing law only)")
            pool = [n for n in (*self.coords, *self.params, *self.inputs) if n in allowed]
            sugg = self.suggest(name, pool)
            return f"; it is not declared{sugg} — {context} may use {_listing(self, allowed)}"
        return hint

    def expr(self, value: object, path: Path, allowed: Container[str], context: str) -> se.Basic:
        if isinstance(value, bool):
            raise self.fail(path, "expected a number or an expression string, got a boolean")
        if isinstance(value, int):
            self.integer_in_range(value, path)
            return se.Integer(value)
        if isinstance(value, float):
            if not math.isfinite(value):
                raise self.fail(path, f"expected a finite number, got {value}")
            # the decimal the user wrote (0.7 is 7/10), as in expression strings
            return _number(repr(value))
        if not isinstance(value, str):
            raise self.fail(path, f"expected a number or an expression string, got "
                            f"{_type_name(value)}")
        try:
            e = parse_expression(value, allowed, describe=self.names_hint(allowed, context),
                                 symbol=self.symbol)
        except ExpressionError as exc:
            col = f" at column {exc.column}" if exc.column else ""
            raise self.fail(path, f'in expression "{_clip(value)}"{col}: {exc}') from None
        self.real_at_defaults(e, value, path)
        return e

    def symbol(self, name: str) -> se.Basic:
        """The symbol of a name: a kinematic quantity's own symbol, or a plain one."""
        q = self.quantity_symbols.get(name)
        return q if q is not None else se.Symbol(name)

    def real_at_defaults(self, e: se.Basic, text: str, path: Path) -> None:
        """An expression of the parameters alone must be a finite real number at their default
        values (``sqrt(-l1)``, ``1/(l1 - 1)`` with l1 = 1 are refused where they are written);
        expressions of coordinates, rates, inputs or t are checked when evaluated."""
        syms = e.free_symbols
        if not syms or not all(str(x) in self.params for x in syms):
            return
        values = {x: self.params[str(x)] for x in syms}
        at = e.subs(values)
        try:
            v = float(at)
        except (RuntimeError, TypeError, ValueError, OverflowError):
            v = math.nan
        if not math.isfinite(v):
            given = ", ".join(f"{x} = {values[x]:g}" for x in sorted(values, key=str))
            raise self.fail(path, f'"{_clip(text)}" is not a finite real number at the default '
                            f"parameter values ({given}): it is {_clip(str(at))}")

    def vector(self, value: object, path: Path, allowed: Container[str], context: str,
               n: int = 3) -> tuple[se.Basic, ...]:
        if not isinstance(value, list):
            raise self.fail(path, f"expected a {n}-vector (an array of {n} numbers or "
                            f"expressions), got {_type_name(value)}")
        if len(value) != n:
            raise self.fail(path, f"expected a {n}-vector, got {len(value)} component"
                            f"{'s' if len(value) != 1 else ''}")
        return tuple(self.expr(v, (*path, i), allowed, context) for i, v in enumerate(value))

    def axis(self, value: object, path: Path, allowed: Container[str],
             context: str) -> str | tuple[se.Basic, ...]:
        if isinstance(value, str):
            s = value.strip().lower().lstrip("+")
            if s.lstrip("-") not in ("x", "y", "z"):
                raise self.fail(path, f'expected one of x, y, z or a 3-vector, got "{value}"')
            return s
        if isinstance(value, list):
            # a direction: the same rule as the Python API (unit_axis), located in the file
            u = unit_axis(self.vector(value, path, allowed, context))
            if u is None:
                jname = self.joint_of_body.get(path[1]) if path[:1] == ("bodies",) else None
                which = f'the axis of joint "{jname}"' if jname else "the axis"
                raise self.fail(path, f"{which} must not be the zero vector")
            return u
        raise self.fail(path, f"expected one of x, y, z or a 3-vector, got {_type_name(value)}")

    def matrix3(self, value: object, path: Path, allowed: Container[str],
                context: str) -> tuple[tuple[se.Basic, ...], ...]:
        if not isinstance(value, list) or len(value) != 3 or not all(
                isinstance(r, list) for r in value):
            raise self.fail(path, f"expected a 3x3 matrix (an array of 3 rows of 3), got "
                            f"{_type_name(value)}")
        for i, r in enumerate(value):
            if len(r) != 3:
                raise self.fail((*path, i), f"expected a row of 3 entries, got {len(r)}")
        return tuple(tuple(self.expr(v, (*path, i, j), allowed, context)
                           for j, v in enumerate(r)) for i, r in enumerate(value))

    # --- sections -------------------------------------------------------------------------
    def load(self) -> ModelFile:
        too_big = _too_big(len(self.text), self.text)
        if too_big:
            raise ModelFileError(f"{self.file}: {too_big}", self.file, None, (), too_big)
        try:
            data = tomllib.loads(self.text)
        except RecursionError:
            raise self.nesting_error() from None
        except tomllib.TOMLDecodeError as exc:
            msg = str(exc)
            m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
            line = int(m.group(1)) if m else None
            if line is None and "(at end of document)" in msg:
                line = max(1, len(self.text.splitlines()))
            core = re.sub(r"\s*\(at (?:line \d+, column \d+|end of document)\)", "", msg)
            col = f", column {m.group(2)}" if m else ""
            loc = f"{self.file}:{line}" if line else self.file
            raise ModelFileError(f"{loc}: TOML syntax error{col}: {core}", self.file, line,
                                 (), core) from None
        except ValueError as exc:  # a number that Python will not convert (> 4300 digits)
            m = re.search(r"[0-9_]{1000,}", self.text)
            line = self.text.count("\n", 0, m.start()) + 1 if m else None
            loc = f"{self.file}:{line}" if line else self.file
            core = f"a number the TOML reader refuses: {exc}"
            raise ModelFileError(f"{loc}: {core}", self.file, line, (), core) from None
        self.table(data, (), _TOP)
        model = self.table(data.get("model", {}), ("model",),
                           {"name", "description", "view"})
        name = self.line_string(model.get("name", FsPath(self.file).stem), ("model", "name"))
        description = self.string(model.get("description", ""), ("model", "description"))
        view = None
        if "view" in model:
            view = self.string(model["view"], ("model", "view")).lower()
            if view not in ("xy", "xz", "yz", "yx", "zx", "zy", "3d"):
                raise self.fail(("model", "view"), f'expected one of xy, xz, yz or 3d, got '
                                f'"{model["view"]}"')

        self.read_coordinates(data)
        self.read_parameters(data)
        self.read_inputs(data)
        self.check_names()
        bodies = self.read_bodies(data)
        self.read_quantities(data)
        forces = self.read_forces(data)
        try:
            system = System(self.coords, bodies, forces, parameters=self.params,
                            inputs=self.inputs, units=self.units, name=name)
        except ModelFileError:
            raise
        except ModelError as exc:
            raise self.fail(self.locate(str(exc)), str(exc)) from None
        nominal = self.read_nominal(data, system)
        sim = self.read_simulation(data, system)
        loops = None
        if "closing_joints" in data or "loops" in data:
            from ..loops.modelfile import read_loops
            loops = read_loops(self, data, system)
        return ModelFile(self.file, system, description, nominal, sim,
                         tuple(self.descriptions.items()), view, loops)

    def nesting_error(self) -> ModelFileError:
        """The TOML reader recursed too deeply: name the value nested deepest."""
        found = deep_nesting(self.text, _MAX_NESTING)
        why = (f"arrays or inline tables nested too deeply (more than {_MAX_NESTING} levels; "
               "a model file needs a few)")
        if found is None:
            return ModelFileError(f"{self.file}: {why}", self.file, None, (), why)
        path, line = found
        return ModelFileError(f"{self.file}:{line}: {describe_path(path)}: {why}", self.file,
                              line, path, why)

    def locate(self, message: str) -> Path:
        """Best key path for an error the core raised about the assembled system: the element
        named first in the message."""
        found: list[tuple[int, Path]] = []
        for m in re.finditer(r'body "(\w+)"', message):
            if m.group(1) in self.body_names:
                found.append((m.start(), ("bodies", m.group(1))))
        for m in re.finditer(r'joint "(\w+)"', message):
            for b, j in self.joint_of_body.items():
                if j == m.group(1):
                    found.append((m.start(), ("bodies", b, "joint")))
        for m in re.finditer(r'(?:force|spring-damper|torque|bushing) "(\w+)"', message):
            found.append((m.start(), ("forces", m.group(1))))
        for m in re.finditer(r'quantity "(\w+)"', message):
            found.append((m.start(), ("quantities", m.group(1))))
        if found:
            return min(found)[1]
        if "coordinate" in message:
            return ("coordinates",)
        return ()

    def read_coordinates(self, data: dict) -> None:
        path: Path = ("coordinates",)
        if "coordinates" not in data:
            raise self.missing("missing table [coordinates] (the generalized coordinates)")
        coords = data["coordinates"]
        if isinstance(coords, list):
            for i, c in enumerate(coords):
                self.coords.append(self.name(c, (*path, i), "coordinate"))
            return
        tbl = self.table(coords, path, what="a table of coordinates or an array of names")
        for cname, spec in tbl.items():
            p = (*path, cname)
            self.name(cname, p, "coordinate")
            self.coords.append(cname)
            if isinstance(spec, str):  # shorthand: the unit
                self.units[cname] = self.line_string(spec, p)
                continue
            spec = self.table(spec, p, {"unit", "description"},
                              what='a table such as { unit = "rad" }')
            if "unit" in spec:
                self.units[cname] = self.line_string(spec["unit"], (*p, "unit"))
            if "description" in spec:
                self.descriptions[cname] = self.string(spec["description"], (*p, "description"))
        if not self.coords:
            raise self.fail(path, "the model needs at least one coordinate")

    def read_parameters(self, data: dict) -> None:
        path: Path = ("parameters",)
        tbl = self.table(data.get("parameters", {}), path)
        for pname, spec in tbl.items():
            p = (*path, pname)
            self.name(pname, p, "parameter")
            if isinstance(spec, dict):
                spec = self.table(spec, p, {"value", "unit", "description"})
                value = self.number(self.require(spec, "value", p), (*p, "value"))
                if "unit" in spec:
                    self.units[pname] = self.line_string(spec["unit"], (*p, "unit"))
                if "description" in spec:
                    self.descriptions[pname] = self.string(spec["description"],
                                                           (*p, "description"))
            else:
                if isinstance(spec, str):
                    raise self.fail(p, f'a parameter value must be a number, got the string '
                                    f'"{spec}" (parameters are not expressions; write the number)')
                value = self.number(spec, p)
            self.params[pname] = value

    def read_inputs(self, data: dict) -> None:
        path: Path = ("inputs",)
        inputs = data.get("inputs", {})
        if isinstance(inputs, list):
            for i, c in enumerate(inputs):
                self.inputs.append(self.name(c, (*path, i), "input"))
            return
        tbl = self.table(inputs, path, what="a table of inputs or an array of names")
        for iname, spec in tbl.items():
            p = (*path, iname)
            self.name(iname, p, "input")
            self.inputs.append(iname)
            if isinstance(spec, str):
                self.units[iname] = self.line_string(spec, p)
                continue
            spec = self.table(spec, p, {"unit", "description"})
            if "unit" in spec:
                self.units[iname] = self.line_string(spec["unit"], (*p, "unit"))
            if "description" in spec:
                self.descriptions[iname] = self.string(spec["description"], (*p, "description"))

    def check_names(self) -> None:
        seen: dict[str, str] = {}
        groups = (("coordinates", self.coords), ("parameters", list(self.params)),
                  ("inputs", self.inputs))
        for section, names in groups:
            for n in names:
                p: Path = (section, n)
                if n in RESERVED_NAMES:
                    raise self.fail(p, f'"{n}" is a reserved name (a function, a constant, t, '
                                    "world or elongation); choose another name")
                if n in seen:
                    raise self.fail(p, f'"{n}" is already declared in [{seen[n]}]')
                seen[n] = section
        for c in self.coords:
            for suffix in ("_d", "_dd"):
                if c + suffix in seen:
                    raise self.fail((seen[c + suffix], c + suffix),
                                    f'"{c + suffix}" is the name of the rate of coordinate '
                                    f'"{c}"; choose another name')

    # --- bodies ---------------------------------------------------------------------------
    def read_bodies(self, data: dict) -> list[Body]:
        path: Path = ("bodies",)
        if "bodies" not in data:
            raise self.missing("missing table [bodies.<name>] (at least one body)")
        tbl = self.table(data["bodies"], path, what="tables [bodies.<name>]")
        if not tbl:
            raise self.fail(path, "the model needs at least one body")
        for bname in tbl:
            self.name(bname, (*path, bname), "body")
            if bname == WORLD:
                raise self.fail((*path, bname), '"world" is the inertial frame, not a body name')
        self.body_names = list(tbl)
        bodies = [self.read_body(bname, spec) for bname, spec in tbl.items()]
        parents = {b.name: b.parent for b in bodies}
        for b in bodies:
            seen = [b.name]
            while parents.get(seen[-1], WORLD) != WORLD:
                nxt = parents[seen[-1]]
                if nxt in seen:
                    chain = " → ".join([*seen[seen.index(nxt):], nxt])
                    raise self.fail((*path, b.name, "parent"), f"the parents form a cycle "
                                    f"({chain}); every chain of parents must end at \"world\"")
                seen.append(nxt)
        # the bodies keep the file's order (the rows of the equations follow it), so a child
        # written before its parent is an error here as in the Python API
        position = {name: k for k, name in enumerate(self.body_names)}
        for k, b in enumerate(bodies):
            if b.parent != WORLD and position[b.parent] > k:
                line = line_of(self.lines, (*path, b.parent))
                at = f", line {line}" if line else ""
                raise self.fail((*path, b.name, "parent"),
                                f'body "{b.name}" (position {k + 1}) comes before its parent '
                                f'"{b.parent}" (position {position[b.parent] + 1}{at}): list '
                                "parents before their children")
        return bodies

    def read_body(self, bname: str, spec: object) -> Body:
        p: Path = ("bodies", bname)
        spec = self.table(spec, p, {"parent", "joint", "mass", "com", "inertia", "description"})
        parent = self.string(self.require(spec, "parent", p), (*p, "parent"))
        if parent != WORLD and parent not in self.body_names:
            others = [b for b in self.body_names if b != bname]  # a body is not its own parent
            raise self.fail((*p, "parent"), f'unknown parent "{parent}"'
                            f'{self.suggest(parent, others)}; expected "world"'
                            + (f" or one of the bodies {', '.join(others)}" if others else ""))
        if parent == bname:
            raise self.fail((*p, "parent"), "a body cannot be its own parent")
        params = set(self.params)
        ctx = "mass data (parameters only)"
        mass = self.expr(self.require(spec, "mass", p), (*p, "mass"), params, ctx)
        com = self.vector(spec.get("com", [0, 0, 0]), (*p, "com"), params, ctx)
        inertia = self.inertia(self.require(spec, "inertia", p), (*p, "inertia"), mass, params,
                               ctx)
        joint = self.joint(self.require(spec, "joint", p), (*p, "joint"), bname)
        if "description" in spec:
            self.descriptions[bname] = self.string(spec["description"], (*p, "description"))
        try:
            body = Body(bname, parent, joint, mass=mass, com=com, inertia=inertia)
        except ModelError as exc:
            raise self.fail((*p, "inertia") if "inertia" in str(exc) else p, str(exc)) from None
        problem = mass_data_problem(body, self.params)
        if problem:
            key, why = problem
            value = {"mass": mass, "com": None, "inertia": None}[key]
            if value is not None and value.is_Symbol and str(value) in self.params:
                # the mass is a parameter: its value is what is wrong, so say it at its line
                raise self.fail(("parameters", str(value)),
                                f'{why} (the mass of body "{bname}" is this parameter)')
            raise self.fail((*p, key), why)
        return body

    def inertia(self, value: object, path: Path, mass: se.Basic, params: set[str],
                ctx: str) -> Any:
        if isinstance(value, str):
            if value == "point":
                return [0, 0, 0]
            raise self.fail(path, f'expected "point", [Ixx, Iyy, Izz], a 3x3 matrix or a shape '
                            f"table such as {{ rod = {{ length = \"l\", axis = \"x\" }} }}, got "
                            f'"{value}"')
        if isinstance(value, list):
            if value and isinstance(value[0], list):
                return self.matrix3(value, path, params, ctx)
            if len(value) != 3:
                raise self.fail(path, f"expected the 3 principal moments [Ixx, Iyy, Izz] or a "
                                f"3x3 matrix, got {len(value)} entries")
            return list(self.vector(value, path, params, ctx))
        if isinstance(value, dict):
            if len(value) != 1:
                raise self.fail(path, "a shape table has exactly one key: point, rod, disc, "
                                "cylinder or box")
            shape, args = next(iter(value.items()))
            sp = (*path, shape)
            if shape not in _SHAPES:
                raise self.fail(sp, f'unknown shape "{shape}"{self.suggest(shape, list(_SHAPES))}'
                                f"; expected one of {', '.join(_SHAPES)}")
            args = self.table(args, sp, _SHAPES[shape] | {"mass"})
            m = self.expr(args["mass"], (*sp, "mass"), params, ctx) if "mass" in args else mass

            def get(k: str) -> se.Basic:
                return self.expr(self.require(args, k, sp), (*sp, k), params, ctx)

            def ax(default: str) -> str:
                a = args.get("axis", default)
                if a not in ("x", "y", "z"):
                    raise self.fail((*sp, "axis"), f'expected one of x, y, z, got '
                                    f"{_type_name(a)}")
                return str(a)

            if shape == "point":
                return [0, 0, 0]
            if shape == "rod":
                return rod(m, get("length"), ax("x"))
            if shape == "disc":
                return disc(m, get("radius"), ax("z"))
            if shape == "cylinder":
                return cylinder(m, get("radius"), get("length"), ax("z"))
            return box(m, get("a"), get("b"), get("c"))
        raise self.fail(path, f"expected an inertia (see docs/model-format.md), got "
                        f"{_type_name(value)}")

    # --- joints ---------------------------------------------------------------------------
    def joint(self, value: object, p: Path, bname: str) -> Any:
        spec = self.table(value, p, what='a joint table such as { type = "revolute", '
                          'coordinate = "phi", axis = "z" }')
        jtype = self.string(self.require(spec, "type", p), (*p, "type")).lower()
        if jtype not in _JOINT_KEYS:
            raise self.fail((*p, "type"), f'unknown joint type "{jtype}"'
                            f"{self.suggest(jtype, list(_JOINT_KEYS))}; expected one of "
                            f"{', '.join(_JOINT_KEYS)}")
        self.table(spec, p, _JOINT_KEYS[jtype] | _JOINT_COMMON)
        jname = self.name(spec.get("name", bname), (*p, "name"), "joint")
        if jname in self.joint_of_body.values():
            other = next(b for b, j in self.joint_of_body.items() if j == jname)
            raise self.fail((*p, "name"), f'joint name "{jname}" is already used by body '
                            f'"{other}"')
        self.joint_of_body[bname] = jname
        params = set(self.params)
        kin = set(self.coords) | params | {"t"}
        ctx_const = "joint positions and orientations (parameters only)"
        position = self.vector(spec.get("position", [0, 0, 0]), (*p, "position"), params,
                               ctx_const)
        orientation = None
        if "orientation" in spec:
            orientation = self.orientation(spec["orientation"], (*p, "orientation"), params,
                                           ctx_const)
            if not isinstance(orientation, list):  # a list of rotations is one by construction
                why = orientation_problem(orientation, self.params)
                if why:
                    raise self.fail((*p, "orientation"), f'the orientation of joint "{jname}" '
                                    f"{why}")
        kw = {"position": position, "orientation": orientation}

        def coord(key: str) -> se.Symbol:
            v = self.require(spec, key, p)
            return se.Symbol(self.coordinate(v, (*p, key)))

        def coords(n: int) -> list[se.Symbol]:
            v = self.require(spec, "coordinates", p)
            if not isinstance(v, list) or len(v) != n:
                raise self.fail((*p, "coordinates"), f"a {jtype} joint needs an array of {n} "
                                f"coordinates, got {_type_name(v)}")
            return [se.Symbol(self.coordinate(c, (*p, "coordinates", i)))
                    for i, c in enumerate(v)]

        def sequence(default: str) -> str:
            s = self.string(spec.get("sequence", default), (*p, "sequence")).lower()
            ok = {"xyz", "xzy", "yxz", "yzx", "zxy", "zyx", "zxz", "xyx", "xzx", "yxy", "yzy",
                  "zyz"}
            if s not in ok:
                raise self.fail((*p, "sequence"), f'expected a rotation sequence such as "xyz" '
                                f'or "zxz", got "{s}"')
            return s

        ctx_kin = "joints (coordinates, parameters and t)"
        try:
            if jtype == "revolute":
                return Revolute(jname, coord("coordinate"),
                                self.axis(spec.get("axis", "z"), (*p, "axis"), params, ctx_const),
                                **kw)
            if jtype == "prismatic":
                return Prismatic(jname, coord("coordinate"),
                                 self.axis(spec.get("axis", "x"), (*p, "axis"), params,
                                           ctx_const), **kw)
            if jtype == "cylindrical":
                return Cylindrical(jname, coords(2), self.axis(spec.get("axis", "z"),
                                                               (*p, "axis"), params, ctx_const),
                                   **kw)
            if jtype == "universal":
                axes = spec.get("axes", ["x", "y"])
                if not isinstance(axes, list) or len(axes) != 2:
                    raise self.fail((*p, "axes"), f"expected an array of 2 axes, got "
                                    f"{_type_name(axes)}")
                ax = [self.axis(a, (*p, "axes", i), params, ctx_const)
                      for i, a in enumerate(axes)]
                return Universal(jname, coords(2), ax, **kw)
            if jtype == "spherical":
                return Spherical(jname, coords(3), sequence("xyz"), **kw)
            if jtype == "planar":
                normal = self.string(spec.get("normal", "z"), (*p, "normal"))
                if normal not in ("x", "y", "z"):
                    raise self.fail((*p, "normal"), f'expected one of x, y, z, got "{normal}"')
                return Planar(jname, coords(3), normal, **kw)
            if jtype == "free":
                return Free(jname, coords(6), sequence("xyz"), **kw)
            if jtype == "fixed":
                return Fixed(jname, **kw)
            steps = self.steps(self.require(spec, "steps", p), (*p, "steps"), kin, ctx_kin)
            driven = []
            if "coordinates" in spec:
                v = spec["coordinates"]
                if not isinstance(v, list):
                    raise self.fail((*p, "coordinates"), f"expected an array of coordinate "
                                    f"names, got {_type_name(v)}")
                driven = [se.Symbol(self.coordinate(c, (*p, "coordinates", i)))
                          for i, c in enumerate(v)]
            else:
                used = set().union(*(_free(s) for s in steps)) & set(self.coords)
                driven = [se.Symbol(c) for c in self.coords if c in used]
            constrained = None
            if "constrained" in spec:
                constrained = self.constrained(spec["constrained"], (*p, "constrained"), params)
            return General(jname, steps, coordinates=driven, constrained=constrained, **kw)
        except ModelFileError:
            raise
        except ModelError as exc:
            raise self.fail(p, str(exc)) from None

    def constrained(self, value: object, path: Path, params: set[str]) -> list[Any]:
        """Constrained directions of a general joint: "F_x" … "T_z" or
        { name = "T_a", wrench = [F_x, F_y, F_z, T_x, T_y, T_z] } (child frame)."""
        if not isinstance(value, list):
            raise self.fail(path, f'expected an array of directions such as ["F_x", "T_y"], got '
                            f"{_type_name(value)}")
        out: list[Any] = []
        units = ("F_x", "F_y", "F_z", "T_x", "T_y", "T_z")
        for i, item in enumerate(value):
            ip = (*path, i)
            if isinstance(item, str):
                if item not in units:
                    raise self.fail(ip, f'expected one of {", ".join(units)} or a table '
                                    f'{{ name = "T_a", wrench = [...] }}, got "{item}"')
                out.append(item)
                continue
            tb = self.table(item, ip, {"name", "wrench"})
            nm = self.name(self.require(tb, "name", ip), (*ip, "name"), "direction")
            w = self.vector(self.require(tb, "wrench", ip), (*ip, "wrench"),
                            params | set(self.coords), "constrained directions (coordinates "
                            "and parameters)", n=6)
            out.append((nm, w))
        return out

    def coordinate(self, value: object, path: Path, drive: bool = True) -> str:
        s = self.string(value, path)
        if s not in self.coords:
            raise self.fail(path, f'"{s}" is not a declared coordinate'
                            f"{self.suggest(s, self.coords)}; coordinates are "
                            f"{', '.join(self.coords)}")
        if drive and path[0] == "bodies":
            other = self.driven.get(s)
            if other is not None and other != path[1]:
                raise self.fail(path, f'coordinate "{s}" is already driven by the joint of body '
                                f'"{other}"; each coordinate belongs to one joint')
            self.driven[s] = str(path[1])
        return s

    def orientation(self, value: object, path: Path, params: set[str], ctx: str) -> Any:
        if isinstance(value, list) and value and all(isinstance(r, dict) for r in value):
            rots = self.steps(value, path, params, ctx)
            if any(isinstance(s, Trans) for s in rots):
                raise self.fail(path, "an orientation is made of rotations only ({ rot = ..., "
                                "angle = ... })")
            return list(rots)
        return self.matrix3(value, path, params, ctx)

    def steps(self, value: object, path: Path, allowed: set[str], ctx: str) -> list[Rot | Trans]:
        if not isinstance(value, list) or not value:
            raise self.fail(path, f'expected an array of steps such as {{ rot = "z", angle = '
                            f'"phi" }} or {{ trans = "x", distance = "s" }}, got '
                            f"{_type_name(value)}")
        out: list[Rot | Trans] = []
        for i, st in enumerate(value):
            sp = (*path, i)
            st = self.table(st, sp, {"rot", "angle", "trans", "distance"},
                            what='a step table such as { rot = "z", angle = "phi" }')
            if "rot" in st:
                if "trans" in st or "distance" in st:
                    raise self.fail(sp, "a step is either a rotation (rot, angle) or a "
                                    "translation (trans, distance), not both")
                ax = self.axis(st["rot"], (*sp, "rot"), set(self.params), ctx)
                angle = self.expr(self.require(st, "angle", sp), (*sp, "angle"), allowed, ctx)
                out.append(Rot(ax, angle))
            elif "trans" in st:
                if "angle" in st:
                    raise self.fail((*sp, "angle"), "a translation step has a distance, not an "
                                    "angle")
                tr = st["trans"]
                if isinstance(tr, list) and "distance" not in st:
                    out.append(Trans(vector=self.vector(tr, (*sp, "trans"), allowed, ctx)))
                else:
                    ax = self.axis(tr, (*sp, "trans"), set(self.params), ctx)
                    dist = self.expr(self.require(st, "distance", sp), (*sp, "distance"),
                                     allowed, ctx)
                    out.append(Trans(ax, dist))
            else:
                raise self.fail(sp, 'a step needs "rot" (with "angle") or "trans" (with '
                                '"distance", or a 3-vector)')
        return out

    # --- forces ---------------------------------------------------------------------------
    def read_forces(self, data: dict) -> list[Any]:
        path: Path = ("forces",)
        tbl = self.table(data.get("forces", {}), path, what="tables [forces.<name>]")
        out = []
        for fname, spec in tbl.items():
            out.append(self.force(fname, spec, (*path, fname)))
        return out

    def force(self, fname: str, spec: object, p: Path) -> Any:
        self.name(fname, p, "force")
        spec = self.table(spec, p, what='a force table with a "type"')
        ftype = self.string(self.require(spec, "type", p), (*p, "type")).lower()
        if ftype not in _FORCE_KEYS:
            raise self.fail((*p, "type"), f'unknown force type "{ftype}"'
                            f"{self.suggest(ftype, list(_FORCE_KEYS))}; expected one of "
                            f"{', '.join(_FORCE_KEYS)}")
        self.table(spec, p, _FORCE_KEYS[ftype] | {"type", "description"})
        rates = {f"{c}_d" for c in self.coords}
        allowed = (set(self.coords) | rates | set(self.params) | set(self.inputs) | {"t"}
                   | set(self.quantity_symbols))
        ctx = "forces (coordinates, rates, parameters, inputs, t and kinematic quantities)"
        params = set(self.params)
        pctx = "points (parameters only)"

        def body(key: str, world_ok: bool) -> str:
            b = self.string(self.require(spec, key, p), (*p, key))
            ok = self.body_names + ([WORLD] if world_ok else [])
            if b not in ok:
                raise self.fail((*p, key), f'unknown body "{b}"{self.suggest(b, ok)}; expected '
                                f"one of {', '.join(ok)}")
            return b

        def frame() -> str:
            fr = self.string(spec.get("frame", WORLD), (*p, "frame"))
            ok = [WORLD, *self.body_names]
            if fr not in ok:
                raise self.fail((*p, "frame"), f'unknown frame "{fr}"; expected "world" or a '
                                "body name")
            return fr

        def e(key: str, default: object = None, names: set[str] = allowed,
              context: str = ctx) -> se.Basic:
            v = spec.get(key, default) if default is not None else self.require(spec, key, p)
            return self.expr(v, (*p, key), names, context)

        try:
            if ftype == "gravity":
                return Gravity(self.vector(self.require(spec, "vector", p), (*p, "vector"),
                                           params | {"t"}, "gravity (parameters and t)"),
                               name=fname)
            if ftype == "force":
                return Force(fname, body("body", False),
                             self.vector(self.require(spec, "vector", p), (*p, "vector"),
                                         allowed, ctx),
                             self.vector(spec.get("point", [0, 0, 0]), (*p, "point"), params,
                                         pctx), frame())
            if ftype == "torque":
                return Torque(fname, body("body", False),
                              self.vector(self.require(spec, "vector", p), (*p, "vector"),
                                          allowed, ctx), frame())
            if ftype == "spring_damper":
                law = None
                if "law" in spec:
                    law = e("law", names=allowed | {"elongation", "elongation_d"},
                            context="a spring law (elongation, elongation_d, coordinates, "
                            "rates, parameters, inputs and t)")
                return SpringDamper(
                    fname, body("body_a", True),
                    self.vector(spec.get("point_a", [0, 0, 0]), (*p, "point_a"), params, pctx),
                    body("body_b", True),
                    self.vector(spec.get("point_b", [0, 0, 0]), (*p, "point_b"), params, pctx),
                    stiffness=e("stiffness", 0), damping=e("damping", 0),
                    rest_length=e("rest_length", 0), law=law)
            if ftype == "bushing":
                return self.bushing(fname, spec, p, body, e, params, pctx, allowed)
            defl = allowed | {"deflection", "deflection_d"}
            vctx = ("a generalized force (deflection, deflection_d, coordinates, rates, "
                    "parameters, inputs, t and kinematic quantities)")
            if ftype == "generalized":
                c = self.generalized_coordinate(spec, p)
                return GeneralizedForce(fname, c, e("value", names=defl, context=vctx))
            c = self.generalized_coordinate(spec, p)
            return RotationalSpringDamper(fname, c, stiffness=e("stiffness", 0),
                                          damping=e("damping", 0),
                                          rest_angle=e("rest_angle", 0, params | {"t"},
                                                       "a rest angle (parameters and t)"))
        except ModelFileError:
            raise
        except ModelError as exc:
            raise self.fail(p, str(exc)) from None

    def generalized_coordinate(self, spec: dict, p: Path) -> se.Basic:
        """A generalized force's ``coordinate``: a coordinate's name, or an expression of the
        coordinates, the parameters, t and the position quantities (``"phi2 - phi1"``)."""
        value = self.require(spec, "coordinate", p)
        if isinstance(value, str) and value.strip() in self.coords:
            return se.Symbol(self.coordinate(value.strip(), (*p, "coordinate")))
        names = (set(self.coords) | set(self.params) | {"t"}
                 | {n for n, s in self.quantity_symbols.items()
                    if not s.quantity.uses_rates})  # type: ignore[attr-defined]
        e = self.expr(value, (*p, "coordinate"), names,
                      "a generalized coordinate (coordinates, parameters, t and position "
                      "quantities)")
        if not {str(x) for x in e.free_symbols} & (set(self.coords)
                                                   | set(self.quantity_symbols)):
            raise self.fail((*p, "coordinate"), f'"{value}" depends on no coordinate')
        return e

    def bushing(self, fname: str, spec: dict, p: Path, body: Callable, e: Callable,
                params: set[str], pctx: str, allowed: set[str]) -> Bushing:
        """A ``type = "bushing"`` force table."""
        fr = spec.get("frame")
        if fr is not None:
            fr = self.string(fr, (*p, "frame"))
        a, b = body("body_a", True), body("body_b", True)
        if fr is not None and fr not in (a, b):
            raise self.fail((*p, "frame"), f'frame "{fr}" must be one of the bushing\'s bodies, '
                            f'"{a}" or "{b}"')

        def six(key: str, matrix: bool) -> object:
            v = spec.get(key, 0)
            kp = (*p, key)
            if v == 0 and not isinstance(v, bool) and matrix:
                return 0
            if not isinstance(v, list) or len(v) != 6:
                what = "a 6-vector (the diagonal) or 6 rows of 6" if matrix else "a 6-vector"
                raise self.fail(kp, f"expected {what}, got {_type_name(v)}")
            if matrix and all(isinstance(r, list) for r in v):
                for i, r in enumerate(v):
                    if len(r) != 6:
                        raise self.fail((*kp, i), f"expected a row of 6 entries, got {len(r)}")
                return [[self.expr(x, (*kp, i, j), allowed, ctx) for j, x in enumerate(r)]
                        for i, r in enumerate(v)]
            return [self.expr(x, (*kp, i), allowed, ctx) for i, x in enumerate(v)]

        ctx = "a bushing (coordinates, rates, parameters, inputs, t and kinematic quantities)"
        axes = {}
        for key in ("axes_a", "axes_b"):
            if key in spec:
                axes[key] = self.orientation(spec[key], (*p, key), params,
                                             "a bushing's axes (parameters only)")
                why = orientation_problem(
                    axes[key] if not isinstance(axes[key], list) else _product(axes[key]),
                    self.params)
                if why:
                    raise self.fail((*p, key), f"the axes {why}")
        laws = {}
        if "laws" in spec:
            tbl = self.table(spec["laws"], (*p, "laws"), set(BUSHING_COMPONENTS),
                             what="a table of laws by component (x, y, z, rx, ry, rz)")
            for comp, law in tbl.items():
                laws[comp] = self.expr(law, (*p, "laws", comp),
                                       allowed | {"deflection", "deflection_d"},
                                       "a bushing law (deflection, deflection_d, coordinates, "
                                       "rates, parameters, inputs, t and kinematic quantities)")
        return Bushing(fname, a, b,
                       self.vector(spec.get("point_a", [0, 0, 0]), (*p, "point_a"), params, pctx),
                       self.vector(spec.get("point_b", [0, 0, 0]), (*p, "point_b"), params, pctx),
                       stiffness=six("stiffness", True), damping=six("damping", True),
                       preload=six("preload", False) if "preload" in spec else (0,) * 6,
                       frame=fr, laws=laws, **axes)

    # --- kinematic quantities -------------------------------------------------------------
    def read_quantities(self, data: dict) -> None:
        """[quantities.<name>]: kinematic quantities for force laws (symbols ``<name>_x``,
        ``<name>_y``, ``<name>_z`` of a vector, ``<name>`` of a distance)."""
        path: Path = ("quantities",)
        tbl = self.table(data.get("quantities", {}), path, what="tables [quantities.<name>]")
        taken = {*self.coords, *(f"{c}_d" for c in self.coords),
                 *(f"{c}_dd" for c in self.coords), *self.params, *self.inputs}
        params = set(self.params)
        pctx = "points (parameters only)"
        for qname, spec in tbl.items():
            p: Path = (*path, qname)
            self.name(qname, p, "quantity")
            spec = self.table(spec, p, what='a quantity table with a "type"')
            kind = self.string(self.require(spec, "type", p), (*p, "type")).lower()
            if kind not in QUANTITY_KINDS:
                raise self.fail((*p, "type"), f'unknown quantity type "{kind}"'
                                f"{self.suggest(kind, list(QUANTITY_KINDS))}; expected one of "
                                f"{', '.join(QUANTITY_KINDS)}")
            two = QUANTITY_KINDS[kind][1]
            self.table(spec, p, (_QUANTITY_KEYS_TWO if two else _QUANTITY_KEYS_ONE)
                       | {"type", "description"})
            ok = [WORLD, *self.body_names]

            def frame_name(key: str, default: str | None, spec: dict = spec, p: Path = p,
                           ok: list = ok) -> str:
                if default is None:
                    v = self.string(self.require(spec, key, p), (*p, key))
                else:
                    v = self.string(spec.get(key, default), (*p, key))
                if v not in ok:
                    raise self.fail((*p, key), f'unknown body "{v}"{self.suggest(v, ok)}; '
                                    f"expected one of {', '.join(ok)}")
                return v

            try:
                if two:
                    qa = frame_name("body_a", None)
                    q = make_quantity(
                        kind, qname, qa,
                        self.vector(spec.get("point_a", [0, 0, 0]), (*p, "point_a"), params,
                                    pctx),
                        frame=frame_name("frame", WORLD), body_b=frame_name("body_b", None),
                        point_b=self.vector(spec.get("point_b", [0, 0, 0]), (*p, "point_b"),
                                            params, pctx))
                else:
                    qb = frame_name("body", None)
                    default_frame = qb if kind == "angular_velocity" else WORLD
                    if kind == "angular_velocity" and ("point" in spec or "point_frame" in spec):
                        raise self.fail(p, "an angular velocity has no point")
                    q = make_quantity(
                        kind, qname, qb,
                        self.vector(spec.get("point", [0, 0, 0]), (*p, "point"), params, pctx),
                        frame=frame_name("frame", default_frame),
                        point_frame=frame_name("point_frame", qb))
            except ModelFileError:
                raise
            except ModelError as exc:
                raise self.fail(p, str(exc)) from None
            for sym in declare_quantity(q):
                n = str(sym)
                if n in taken or n in RESERVED_NAMES:
                    raise self.fail(p, f'its symbol "{n}" is already a declared or reserved name; '
                                    "choose another name for the quantity")
                taken.add(n)
                self.quantity_symbols[n] = sym
            if "description" in spec:
                self.descriptions[qname] = self.string(spec["description"], (*p, "description"))

    # --- nominal motions and simulation ---------------------------------------------------
    def read_nominal(self, data: dict, system: System) -> tuple[NominalMotion, ...]:
        path: Path = ("nominal",)
        tbl = self.table(data.get("nominal", {}), path, what="tables [nominal.<name>]")
        allowed = set(self.params) | {"t"}
        ctx = "a nominal motion (parameters and t)"
        t = se.Symbol("t")
        out = []
        for nname, spec in tbl.items():
            p = (*path, nname)
            self.name(nname, p, "nominal motion")
            spec = self.table(spec, p, {"y", "yd", "inputs", "description", "period"})

            def values(key: str, spec: dict = spec, p: Path = p) -> dict[str, se.Basic]:
                tb = self.table(spec.get(key, {}), (*p, key),
                                what="a table of coordinate = value")
                out: dict[str, se.Basic] = {}
                for c, v in tb.items():
                    if c not in self.coords:
                        raise self.fail((*p, key, c), f'"{c}" is not a declared coordinate'
                                        f"{self.suggest(c, self.coords)}")
                    out[c] = self.expr(v, (*p, key, c), allowed, ctx)
                return out

            y = values("y")
            y_full = tuple(y.get(c, se.Integer(0)) for c in self.coords)
            if "yd" in spec:
                yd = values("yd")
                yd_full = tuple(yd.get(c, se.diff(y.get(c, se.Integer(0)), t))
                                for c in self.coords)
            else:
                yd_full = tuple(se.diff(e, t) for e in y_full)
            ydd_full = tuple(se.diff(e, t) for e in yd_full)
            desc = self.string(spec.get("description", ""), (*p, "description"))
            ins = []
            for iname, v in self.table(spec.get("inputs", {}), (*p, "inputs"),
                                       what="a table of input = value").items():
                if iname not in self.inputs:
                    raise self.fail((*p, "inputs", iname), f'"{iname}" is not a declared input'
                                    f"{self.suggest(iname, self.inputs)}")
                ins.append((iname, self.expr(v, (*p, "inputs", iname), allowed, ctx)))
            period = None
            if "period" in spec:
                period = self.expr(spec["period"], (*p, "period"), set(self.params),
                                   "a period (parameters only)")
                value = float(period.subs({se.Symbol(k): v for k, v in self.params.items()}))
                if not value > 0:
                    raise self.fail((*p, "period"), f"the period must be positive, it is "
                                    f"{value:g} at the default parameter values")
            out.append(NominalMotion(nname, y_full, yd_full, ydd_full, desc, tuple(ins), period))
        return tuple(out)

    def read_simulation(self, data: dict, system: System) -> SimulationSettings:
        p: Path = ("simulation",)
        spec = self.table(data.get("simulation", {}), p,
                          {"t_end", "samples", "method", "rtol", "atol", "y0", "yd0", "inputs"})
        kw: dict[str, Any] = {}
        checks = {"t_end": check_t_end, "rtol": check_rtol,
                  "atol": lambda v, name: check_atol(v, 1, name)[0],
                  "samples": lambda v, name: check_samples(v, system.f, len(system.inputs),
                                                           name)}
        for k, check in checks.items():
            if k in spec:
                v = self.number(spec[k], (*p, k), positive=True, integer=k == "samples")
                try:  # the bounds of jourdain.simulation.simulate, one place for the API and the files
                    kw[k] = check(v, k)
                except JourdainError as exc:
                    raise self.fail((*p, k), str(exc)) from None
        if "method" in spec:
            methods = ("DOP853", "RK45", "Radau", "BDF", "LSODA")
            m = self.string(spec["method"], (*p, "method"))
            if m not in methods:
                raise self.fail((*p, "method"), f'unknown method "{m}"'
                                f"{self.suggest(m, list(methods))}; expected one of "
                                f"{', '.join(methods)}")
            kw["method"] = m
        nums: set[str] = set()  # initial values are constant expressions (pi/4)
        for key in ("y0", "yd0"):
            tb = self.table(spec.get(key, {}), (*p, key), what="a table of coordinate = value")
            vals = {}
            for c, v in tb.items():
                cname = c[:-2] if key == "yd0" and c.endswith("_d") else c
                if cname not in self.coords:
                    raise self.fail((*p, key, c), f'"{c}" is not a declared coordinate'
                                    f"{self.suggest(c, self.coords)}")
                ex = self.expr(v, (*p, key, c), nums | set(self.params),
                               "initial values (numbers and parameters)")
                vals[cname] = float(ex.subs({se.Symbol(k): x for k, x in self.params.items()}))
            kw[key] = tuple(vals.get(c, 0.0) for c in self.coords)
        tb = self.table(spec.get("inputs", {}), (*p, "inputs"),
                        what="a table of input = expression in t")
        ins = []
        for iname, v in tb.items():
            if iname not in self.inputs:
                raise self.fail((*p, "inputs", iname), f'"{iname}" is not a declared input'
                                f"{self.suggest(iname, self.inputs)}")
            ins.append((iname, self.expr(v, (*p, "inputs", iname), set(self.params) | {"t"},
                                         "input laws (parameters and t)")))
        kw["inputs"] = tuple(ins)
        kw.setdefault("y0", tuple(0.0 for _ in self.coords))
        kw.setdefault("yd0", tuple(0.0 for _ in self.coords))
        return SimulationSettings(**kw)


def _product(rotations: list) -> Any:
    """The rotation matrix of a list of Rot steps."""
    from ..model.forces import _axes

    return _axes(rotations, "axes")


def _free(step: Rot | Trans) -> set[str]:
    exprs = [step.angle] if isinstance(step, Rot) else list(step.vector)
    return {str(s) for e in exprs for s in e.free_symbols}


def _listing(loader: _Loader, allowed: Container[str]) -> str:
    parts = []
    for label, names in (("coordinates", loader.coords),
                         ("rates", [f"{c}_d" for c in loader.coords]),
                         ("parameters", list(loader.params)), ("inputs", loader.inputs),
                         ("kinematic quantities", list(loader.quantity_symbols))):
        shown = [n for n in names if n in allowed]
        if shown:
            parts.append(f"{label} {', '.join(shown)}")
    if "t" in allowed:
        parts.append("t")
    return "; ".join(parts) if parts else "numbers only"


def loads_model(text: str, filename: str = "<string>") -> ModelFile:
    """Read a model from TOML ``text``; ``filename`` is used in error messages."""
    return _Loader(text, filename).load()


def load_model(path: str | FsPath) -> ModelFile:
    """Read a model file. Raises :class:`ModelFileError` (a :class:`~jourdain.ModelError`)."""
    name = str(path)
    try:
        with open(path, "rb") as fh:
            # at most one byte more than allowed: a huge file (or /dev/zero) is not read whole
            raw = fh.read(MAX_FILE_BYTES + 1)
            size = len(raw)
            if size > MAX_FILE_BYTES:
                try:
                    size = max(size, os.fstat(fh.fileno()).st_size)
                except OSError:
                    pass
    except OSError as exc:
        raise ModelFileError(f"{name}: cannot read the model file: {exc.strerror}", name,
                             None) from None
    too_big = _too_big(size)
    if too_big:
        raise ModelFileError(f"{name}: {too_big}", name, None, (), too_big)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ModelFileError(f"{name}:{line}: the file is not valid UTF-8 text", name,
                             line) from None
    return loads_model(text, name)
