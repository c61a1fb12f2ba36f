"""What a model's simulation evaluates, and its first runs without waiting for the optimizing
compiler (issue 35: "setup in milliseconds": a fast first path while the optimizing compiler
runs in the background).

:func:`run_function` gives :func:`jourdain.numeric.compiled.mkq_function` where its library is
loaded, cached or prebuilt. Where it is not, the first runs take a
:class:`~jourdain.numeric.functions.ProvisionalFunction` while a thread builds the library:

* on the symbolic path, the generated C read by the interpreter of the integrator's library
  (:mod:`jourdain.numeric.interpreter`): nothing compiled before the first number;
* on the recursions' paths (whose engines are C with the model's sizes as constants), the
  same engines in the integrator's library sized at run time, their per-joint code on the
  interpreter (:mod:`jourdain.numeric.runtime_engine`): nothing compiled either;
* where the interpreter cannot read that per-joint code, the recursion's units compiled at
  -O0 under a key of their own: the compiler's front end alone (0.2 against 0.35-0.7 s for
  the 31-link cart and the spatial chains of 8 and 16 bodies), when no ``JOURDAIN_OPTIMIZE``
  level is set (that one is already a short compile).

All give the library's numbers to the bit, so a motion never depends on whether the library
was built yet, and a run moves to the library between two calls of its C loop
(``_Setup.take_compiled``). A forked child builds for itself; a failed build is reported once
by a warning, and the runs stay on the provisional function.
"""

from __future__ import annotations

import os
import warnings
from functools import lru_cache
from typing import TYPE_CHECKING

from .compiled import (
    ALSO_CLEARED,
    ENGINE_FLAGS,
    _refuse_closed,
    _symbolic_parts,
    arguments,
    cached_mkq,
    dynamics_function,
    library_key,
    mkq_function,
    planar_function,
    recursion_units,
)
from .cost import evaluation_path
from .functions import CompiledFunction, ProvisionalFunction
from .integrator_c import integrator_library
from .integrator_ldl import ldl_source
from .interpreter import FirstFunction, Interpreted, Unreadable, program
from .runtime_engine import RuntimeFunction, runtime_function
from .symbolic_accel import accel_source
from .toolchain import CompilerError, build_soon, cached_library, compiler

if TYPE_CHECKING:
    from ..model.system import System

#: the first runs of a symbolic-path model interpreted while its library compiles
FIRST_RUN_INTERPRETED = True
#: the first runs of a recursion-path model on its engine sized at run time while its library
#: compiles
FIRST_RUN_RUNTIME = True
#: else on its -O0 build while the -O2 one compiles
FIRST_RUN_QUICK = True


@lru_cache(maxsize=32)
def _run_function(system: System) -> CompiledFunction:
    """:func:`mkq_function`, or a provisional function while a thread builds it (see the
    module docs)."""
    _refuse_closed(system)
    try:
        compiler()
    except CompilerError:
        return mkq_function(system)
    if cached_mkq(system) is not None:  # a warm start: nothing derived
        return mkq_function(system)  # (the memoized one, which takes the same recipe)
    first: ProvisionalFunction | None = _interpreted(system) if FIRST_RUN_INTERPRETED else None
    path = evaluation_path(system).path
    if first is None and FIRST_RUN_RUNTIME and path in ("planar", "spatial"):
        first = _runtime(system, path == "planar")
    if first is None and FIRST_RUN_QUICK and not os.environ.get("JOURDAIN_OPTIMIZE", "").strip():
        if path in ("planar", "spatial"):
            fn = (planar_function if path == "planar" else dynamics_function)(system, quick=True)
            first = fn if isinstance(fn, ProvisionalFunction) else None
    if first is None:
        return mkq_function(system)
    start = first

    def build_it() -> None:
        try:
            start.compiled.append(mkq_function(system))
        except Exception as exc:  # noqa: BLE001 - reported by run_function, in this thread
            start.failed.append(exc)

    build_soon(build_it, name="jourdain-model-build")
    return first


def _interpreted(system: System) -> FirstFunction | None:
    """The symbolic path's source on the interpreter, where the path is symbolic, its library
    not at hand and its source readable; else None."""
    parts = _symbolic_parts(system)
    if not parts or not accel_source(system.f):
        return None
    names, shapes, source, _ = parts
    key = library_key(source)
    if cached_library(key) is not None:
        return None
    f = system.f
    try:
        prog = program(source, "jd_fn", f, len(system.parameters), len(system.inputs),
                       f * f + 2 * f)
        lib = integrator_library()  # which holds the interpreter (jd_interp_*)
    except (Unreadable, CompilerError):
        return None
    return FirstFunction(names, shapes, arguments(system), key, f, len(system.parameters),
                         len(system.inputs), lib, interp=Interpreted(prog, bool(ldl_source(f))))


def _runtime(system: System, planar: bool) -> RuntimeFunction | None:
    """The recursion's engine sized at run time, where the path is a recursion, its library
    not at hand and its per-joint code readable; else None."""
    units = recursion_units(system, planar)
    key = library_key(units, ((), ENGINE_FLAGS))
    if cached_library(key) is not None:
        return None
    try:
        return runtime_function(system, planar, units, key, arguments(system),
                                integrator_library())
    except (Unreadable, CompilerError):
        return None


def run_function(system: System) -> CompiledFunction:
    """What a simulation of ``system`` evaluates: :func:`mkq_function`, or on the first runs
    of a model whose library is not built yet, a provisional function with the same numbers
    to the bit while a thread builds it (see the module docs); once built, the library."""
    fn = _run_function(system)
    if not isinstance(fn, ProvisionalFunction):
        return fn
    if fn.compiled:
        return fn.compiled[0]
    if fn.failed and not fn.warned:
        fn.warned.append(True)
        warnings.warn(f"the compiled library of {system.name!r} could not be built "
                      f"({fn.failed[0]}); its runs go on without it (interpreted or compiled at "
                      "-O0: the same numbers, slower)", RuntimeWarning, stacklevel=3)
    if fn.pid != os.getpid():
        # a child forked while the build ran: the thread is not in it; it compiles (or loads
        # what the parent built) for itself
        fn.compiled.append(mkq_function(system))
        return fn.compiled[0]
    return fn


ALSO_CLEARED.append(_run_function.cache_clear)
