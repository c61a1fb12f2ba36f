"""The derivation skipped on a warm start (issue 35, item 3: "caching the derivation itself").

A model's compiled library is cached on disk under the hash of its generated C
(:func:`jourdain.numeric.compiled.library_key`), so finding it took the whole derivation, the
cost model's choice of path and the code generation: 12-70 ms for the models of
``benchmarks/setup.py`` (f = 2 … 32), most of a warm start after the imports. A *recipe* is
what :func:`~jourdain.numeric.compiled.mkq_function` made of a model: its path, the key of its
library and the names and shapes of its matrices. It is kept beside the libraries, under a key
formed from

* the model itself, exactly: :func:`fingerprint` writes every field of the ``System`` out in
  full (the expressions node by node, floats by their hexadecimal form), so two models share a
  key only when their descriptions are the same to the bit, down to the order of the terms in
  a sum (which orders the generated code);
* the code that derives and generates (:func:`code_stamp`: the path, size and time of change
  of every ``.py`` and ``.h`` file of the package, so an edited or reinstalled jourdain never
  meets a recipe of its old self), the settings of its modules that shape the choice of path
  and the code (:func:`settings`), and SymEngine's version;
* what every library key holds (:func:`jourdain.numeric.toolchain.content_key`: flags,
  optimization level, native target, platform, format of the cache).

A description holding anything :func:`fingerprint` does not know (a function, an object of
another library) gets no recipe: the derivation runs as before. A recipe only names a library;
that library is loaded only under the checks of every cached one (private, sealed, stamped
with its key), and a recipe whose library is gone is ignored. The recipe itself is a sealed
JSON file (data, never code) bound to its key.
"""

from __future__ import annotations

import enum
import hashlib
import json
import math
import os
from dataclasses import fields, is_dataclass
from functools import lru_cache
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..model.quantities import QuantitySymbol
from .cachefile import keep_sealed, read_sealed
from .toolchain import content_key, library_dir

if TYPE_CHECKING:
    from ..model.system import System

#: the version of the recipes' content: part of their key
RECIPE_VERSION = "recipe-1"
#: the most tokens a fingerprint may hold (a description larger than this gets no recipe: its
#: derivation is long anyway, and the walk should stay a small part of a start)
MAX_TOKENS = 200_000

#: SymEngine atoms written as their class and their text (exact for each of these)
_ATOMS = ("Symbol", "Integer", "Rational", "Constant", "BooleanAtom", "Infinity",
          "NegativeInfinity", "ComplexInfinity", "NaN", "Zero", "One", "NegativeOne", "Half",
          "BooleanTrue", "BooleanFalse", "Pi", "E", "EulerGamma", "Catalan", "GoldenRatio")


class _Unknown(Exception):
    """Something in the description that :func:`fingerprint` cannot write exactly."""


def fingerprint(system: System) -> str | None:
    """The exact description of ``system`` as text (see the module docs), or None where it
    holds something that cannot be written exactly, or more than :data:`MAX_TOKENS` pieces."""
    out: list[str] = []
    try:
        _write(system, out)
    except (_Unknown, RecursionError):
        return None
    return "\x1f".join(out)


def _write(obj: Any, out: list[str]) -> None:
    if len(out) > MAX_TOKENS:
        raise _Unknown("too large")
    if isinstance(obj, se.Basic):
        _write_expr(obj, out)
    elif obj is None or isinstance(obj, bool):
        out.append(repr(obj))
    elif isinstance(obj, enum.Enum):
        out.append(f"E{type(obj).__qualname__}.{obj.name}")
    elif isinstance(obj, int):
        out.append(f"i{obj}")
    elif isinstance(obj, float):
        out.append(f"f{obj.hex()}" if math.isfinite(obj) else f"f{obj!r}")
    elif isinstance(obj, str):
        out.append("s" + json.dumps(obj))
    elif isinstance(obj, tuple | list):
        out.append(f"({len(obj)}")
        for item in obj:
            _write(item, out)
    elif isinstance(obj, dict | MappingProxyType):
        out.append(f"{{{len(obj)}")
        for k, v in obj.items():
            _write(k, out)
            _write(v, out)
    elif isinstance(obj, np.ndarray) and obj.dtype.kind in "biuf":  # modal data and the like
        data = np.ascontiguousarray(obj)
        out.append(f"a{data.dtype.str}{data.shape}:{hashlib.sha256(data.tobytes()).hexdigest()}")
    elif is_dataclass(obj) and not isinstance(obj, type):
        cls = type(obj)
        fs = fields(obj)
        out.append(f"D{cls.__module__}.{cls.__qualname__}:{len(fs)}")
        for f in fs:
            out.append(f.name)
            _write(getattr(obj, f.name), out)
    else:
        raise _Unknown(type(obj).__qualname__)


def _write_expr(e: se.Basic, out: list[str]) -> None:
    """An expression node by node: its class, then its arguments in SymEngine's order (which
    is the order the derivation and the generated code see)."""
    stack: list[se.Basic] = [e]
    while stack:
        if len(out) > MAX_TOKENS:
            raise _Unknown("too large")
        node = stack.pop()
        name = type(node).__name__
        if type(node).__module__ != se.Basic.__module__:  # a subclass of ours, or of a user's
            if not isinstance(node, QuantitySymbol):
                raise _Unknown(name)
            out.append(f"Q{node}:{node.component}")
            _write(node.quantity, out)
            continue
        args = node.args
        if not args:
            if name == "RealDouble":
                out.append(f"R{float(node).hex()}")
            elif name in _ATOMS:
                out.append(f"A{name}:{node}")
            else:  # a Dummy (named alike, told apart by an index of the process), an MPFR
                raise _Unknown(name)
            continue
        if name == "FunctionSymbol":  # an undefined function: its name is not an argument
            name = f"{name}:{node.get_name()}"
        out.append(f"N{name}:{len(args)}")
        stack.extend(reversed(args))


@lru_cache(maxsize=1)
def code_stamp() -> str:
    """The path, size and time of change of every ``.py`` and ``.h`` file of the installed
    package, hashed (once per process; about 2 ms): a recipe is of this code only."""
    root = Path(__file__).resolve().parents[1]
    items: list[str] = []
    _stat_tree(str(root), items)
    return hashlib.sha256("\n".join(items).encode()).hexdigest()


def _stat_tree(d: str, items: list[str]) -> None:
    with os.scandir(d) as it:
        entries = sorted(it, key=lambda e: e.name)
    for e in entries:
        if e.is_dir(follow_symlinks=False):
            if e.name not in ("__pycache__", "prebuilt"):
                _stat_tree(e.path, items)
        elif e.name.endswith((".py", ".h")):
            st = e.stat()
            items.append(f"{e.path}\0{st.st_size}\0{st.st_mtime_ns}")


def settings(*more: object) -> str:
    """The module settings that shape the choice of path and the generated code, read now (a
    user, or a test, may set them in the process), with ``more`` of the caller's."""
    from ..graph import identity
    from . import ccode, cost, integrator_ldl, planar_recursion, symbolic_accel

    costs = sorted((k, sorted(v.items())) for k, v in cost.COST_NS.items())
    return repr((costs, cost.SYMBOLIC_MAX_NODES, cost.SYMBOLIC_MAX_F,
                 planar_recursion.PLANE_MAX_BODIES, symbolic_accel.ACCEL_MAX_F,
                 ccode.SPLIT_ABOVE, ccode.TRIG_SUMS, ccode.PART, ccode.SHARE_SUMS,
                 integrator_ldl.WRITTEN_OUT_MAX_F, identity.POINTERS, *more))


def recipe_key(system: System, what: str, *more: object) -> str | None:
    """The key of the recipe of ``what`` (the function's name) for ``system`` under the
    current :func:`settings` (with ``more``), or None where the system cannot be written
    exactly (:func:`fingerprint`)."""
    text = fingerprint(system)
    if text is None:
        return None
    return content_key(RECIPE_VERSION, what, code_stamp(), se.__version__, settings(*more),
                       text)


def _path(key: str) -> Path:
    return library_dir() / f"{key}.recipe"


def load_recipe(key: str) -> dict | None:
    """The recipe kept under ``key``, or None (none, damaged, or of another key)."""
    data = read_sealed(_path(key))
    if data is None:
        return None
    try:
        rec = json.loads(data)
    except ValueError:
        return None
    return rec if isinstance(rec, dict) and rec.get("recipe") == key else None


def keep_recipe(key: str, recipe: dict) -> None:
    """Keep ``recipe`` (JSON data) under ``key``; one that cannot be written costs time only."""
    keep_sealed(_path(key), json.dumps({**recipe, "recipe": key}, sort_keys=True).encode())
