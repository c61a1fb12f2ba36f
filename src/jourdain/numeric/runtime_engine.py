"""The first runs of a recursion-path model without a compiler: its engine sized at run time
(issue 35: "setup in milliseconds").

A planar or spatial model's library is two units (:mod:`jourdain.numeric.planar_recursion`,
:mod:`jourdain.numeric.recursive`): the generated per-joint code ``jd_local`` and the engine,
``planar_engine.h`` or ``recursive_engine.h`` with the model's sizes as constants and its tables
as static arrays. The integrator's library holds the same engines' text compiled once with the
sizes and tables read from a context instead (``runtime_head.h``, ``runtime_engine.h``), and
here ``jd_local`` is read by the interpreter (:mod:`jourdain.numeric.interpreter`) and the
sizes and tables from the engine unit's own head: :func:`runtime_function` gives a
:class:`RuntimeFunction` with nothing compiled. Where the articulated-body recursion applies,
``ÿ`` is the engine's; elsewhere M, k, q and then the solve of the library's ``jd_accel``
(the interpreter's ``jd_interp_solve``: written out where the planar library writes it out,
else the loop).

The same operations on the same operands in the same order as the library's (the engines'
one text, the flags of :data:`jourdain.numeric.toolchain.CFLAGS`: no contraction, no
reassociation), so the numbers are the library's to the bit, which the tests check, and a run
may move from one to the other between two calls of its C loop (``_Setup.take_compiled``).
Where the per-joint code holds what the interpreter does not read, or the library has no
``jd_accel`` (more than ``ACCEL_MAX_F`` coordinates, no articulated bodies), it gives up
(:class:`~jourdain.numeric.interpreter.Unreadable`), and the first run takes the units
compiled at -O0 as before (:mod:`jourdain.numeric.first_run`).
"""

from __future__ import annotations

import ctypes
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .functions import ContextFunction
from .integrator_ldl import ldl_source
from .interpreter import Interpreted, Program, Unreadable, _body, _Reader
from .recursive import BODY_BLOCK
from .symbolic_accel import ACCEL_MAX_F

if TYPE_CHECKING:
    from ..model.system import System

_DEFINE = re.compile(r"^#define (JD_\w+) (\d+)$", re.M)
_TABLE = re.compile(r"^static const int (jd_\w+)\[\d+\] = \{([^}]*)\};$", re.M)


def local_program(source: str, f: int, n_p: int, n_u: int, n_out: int) -> Program:
    """The program of ``jd_local`` in ``source`` (:func:`jourdain.numeric.ccode.function_source`
    without ``whole`` or ``symmetric``: one function, or above ``SPLIT_ABOVE`` its parts
    sharing the temporaries ``x``); :class:`Unreadable` where it is not of that form."""
    reader = _Reader(f, n_p, n_u)
    lines = _body(source, "\nvoid jd_local(")
    try:
        if not any("malloc" in line for line in lines):
            for line in lines:
                reader.statement(line)
            return reader.finish(n_out, [])
        for line in lines:
            s = line.strip()
            m = re.fullmatch(r"jd_local_part(\d+)\(y, yd, t, p, u, out, x\);", s)
            if m:
                for inner in _body(source, f"static void jd_local_part{m.group(1)}("):
                    reader.statement(inner)
            elif s.startswith(("double jd_a[", "jd_a[", "jd_sincos_n(")):
                reader.statement(s)
            elif not (s in ("", "{", "}", "free(x);") or s.startswith(
                    ("/*", "double *x = (double *)malloc(", "if (!x) {"))):
                raise Unreadable(f"unknown statement {s[:80]!r}")
    except RecursionError:
        raise Unreadable("nested too deep") from None
    return reader.finish(n_out, [])


def engine_tables(engine: str) -> tuple[dict[str, int], dict[str, list[int]]]:
    """The sizes (``#define JD_… n``) and tables (``static const int jd_…[]``) at the head of
    an engine unit."""
    sizes = {m.group(1): int(m.group(2)) for m in _DEFINE.finditer(engine)}
    tables = {m.group(1): [int(v) for v in m.group(2).split(",")]
              for m in _TABLE.finditer(engine)}
    return sizes, tables


class _Context(ctypes.Structure):
    """``jd_rt`` of runtime_head.h."""

    _fields_ = [(n, ctypes.c_int) for n in ("p", "f", "nc", "nl", "cols", "written_out")] + [
        (n, ctypes.c_void_p) for n in ("parent", "col_start", "col_coord", "local")] + [
        ("n_reg", ctypes.c_long)]


class RuntimeContext:
    """The context of an engine sized at run time: the program of ``jd_local``, the tables,
    and the C structure that points at them (kept alive together)."""

    def __init__(self, sizes: dict[str, int], tables: dict[str, list[int]], local: Interpreted,
                 n_reg: int, written_out: bool) -> None:
        self.local = local
        self.tables = [np.array(tables[n], dtype=np.intc)
                       for n in ("jd_parent", "jd_col_start", "jd_col_coord")]
        self.struct = _Context(sizes["JD_P"], sizes["JD_F"], sizes["JD_NC"], sizes["JD_NL"],
                               sizes["JD_COLS"], int(written_out),
                               *(t.ctypes.data for t in self.tables), local.address, n_reg)
        self.address = ctypes.addressof(self.struct)


@dataclass(frozen=True, eq=False)
class RuntimeFunction(ContextFunction):
    """The interface of :class:`CompiledFunction` on an engine sized at run time: ``lib`` is the
    integrator's library, ``engine`` ``"plane"`` or ``"spatial"`` (its entry points
    ``jd_rt_<engine>_…``), ``aba`` whether ÿ is the articulated bodies' (else M, k, q and the
    solve); :attr:`accel_ctx_address` and :attr:`ctx_address` are the integrator's right-hand
    side (``jd_problem.accel_ctx``, ``ctx``). ``compiled`` receives the library once built."""

    context: RuntimeContext | None = field(default=None, repr=False)
    engine: str = "spatial"
    aba: bool = False

    def entries(self) -> tuple[Any, Any, Any]:
        e = self.engine
        return (getattr(self.lib, f"jd_rt_{e}_fn"), getattr(self.lib, f"jd_rt_{e}_batch"),
                getattr(self.lib, f"jd_rt_{e}_{'accel' if self.aba else 'ldl'}"))

    @property
    def ctx_address(self) -> int | None:
        return None if self.context is None else self.context.address


def runtime_function(system: System, planar: bool, units: tuple[str, str], key: str,
                     args: tuple, lib: ctypes.CDLL) -> RuntimeFunction:
    """The model's M, k, q and ÿ of the library built from ``units`` (the per-joint code and
    the engine of :func:`jourdain.numeric.compiled.recursion_units`, cached under ``key``) on
    the engine of ``lib`` (the integrator's library) sized at run time; ``args``: the argument
    symbols. :class:`Unreadable` where it cannot give the library's numbers (module docs)."""
    local, engine = units
    sizes, tables = engine_tables(engine)
    f, n_p, n_u = system.f, len(system.parameters), len(system.inputs)
    if sizes.get("JD_F") != f or not planar and sizes.get("JD_BODY") != BODY_BLOCK:
        raise Unreadable("the engine's head")
    aba = bool(sizes["JD_ABA"])
    if not aba and f > ACCEL_MAX_F:
        raise Unreadable(f"no jd_accel above {ACCEL_MAX_F} coordinates")
    prog = local_program(local, f, n_p, n_u, sizes["JD_NL"])
    # the planar library's jd_accel writes its solve out where ldl_source does; the spatial
    # one's takes the loop that its engine holds for the joint wrenches (ldl_solve.h) first
    written = planar and not aba and bool(ldl_source(f))
    context = RuntimeContext(sizes, tables, Interpreted(prog, False), prog.n_reg, written)
    return RuntimeFunction(("M", "k", "q"), ((f, f), (f, 1), (f, 1)), args, key, f, n_p, n_u,
                           lib, context=context, engine="plane" if planar else "spatial",
                           aba=aba)
