"""Compiling a system's matrices: :func:`lambdify` (the generated C of the expression graph),
the recursion's library (:func:`dynamics_function`), the integrator's :func:`mkq_function` and
its ``jd_accel``, memoized per system (:func:`clear_cache`).
"""

from __future__ import annotations

import ctypes
import shutil
import warnings
from collections.abc import Callable, Mapping
from functools import lru_cache
from typing import TYPE_CHECKING

import symengine as se

from ..errors import JourdainError, refuse_closed
from ..graph import count_nodes
from ..stages.kinematics import kinematics  # the model has no stage methods (issue 16)
from ..stages.newton_euler import newton_euler
from ..stages.projection import projection
from ..stages.reactions import joint_directions, reactions
from ..symbolic import SymMatrix
from .cachefile import dump_pickle, keep_sealed, load_pickle
from .ccode import HEADER, argument_names, function_source
from .cost import evaluation_path
from .planar_recursion import planar_units, plane_normal
from .recipes import keep_recipe, load_recipe, recipe_key
from .recursive import layout, recursive_units
from .symbolic_accel import accel_source, symbolic_source
from .toolchain import (
    CompilerError,
    build,
    build_soon,
    cache_dir,
    cached_library,
    compiler,
    content_key,
    library_dir,
)

if TYPE_CHECKING:
    from ..model.system import System
    from ..stages.projection import EquationsOfMotion

from .functions import CompiledFunction, InterpretedFunction, JitFunction, ProvisionalFunction

_GENERATOR_VERSION = "c3"


def arguments(system: System) -> tuple[se.Symbol, ...]:
    """The argument symbols, in order: y, ẏ, t, parameters, inputs."""
    return (*system.y, *system.yd, system.t, *system.parameter_symbols, *system.inputs)


def lambdify(system: System, matrices: Mapping[str, SymMatrix],
             extra_source: str = "", whole: bool = False,
             symmetric: int = 0, lean: bool = False) -> CompiledFunction:
    """Compile the named matrices of ``system`` to machine code.

    Common-subexpression elimination on the expression graph, then C source with one
    statement per temporary, compiled once with the system's C compiler and cached on disk by
    content hash (:func:`cache_dir`); a later call with the same expressions loads the cached
    library instead of compiling again. ``extra_source``: C appended to the generated source
    (it may call ``jd_fn``). ``whole``: ``jd_fn`` is one function however large;
    ``symmetric``: the first matrix is symmetric of that size, and ``jd_fn_upper`` leaves out
    the copies into its lower triangle (:func:`jourdain.numeric.ccode.function_source`).
    ``lean``: compiled for a short compile rather than the fastest code, for a function
    evaluated once per sample of a motion (energies, positions, poses, joint wrenches: a
    report builds four to six after its simulation). Up to :data:`JIT_MAX_NODES` nodes it is
    compiled in this process by SymEngine's LLVM backend (:func:`_jit`: 1-8 ms for the
    robot arm's functions, against 45-75 ms of a compiler process; at most a few ms over 800
    samples) and kept on disk; else, and without LLVM, as C whose sines and cosines are not
    vectorized (``JD_LEAN`` in sincos.h: 45-50 instead of 75 ms for a small function, the
    same numbers to the bit).

    The cache key is a hash of the generated source itself: SymEngine's own hashes cannot serve,
    since they do not tell ``k*(x - x0)`` from ``k*(x0 - x)``.
    """
    names = tuple(matrices)
    shapes = tuple(matrices[n].shape for n in names)
    exprs: list[se.Basic] = []
    for n in names:
        m = matrices[n]
        if not isinstance(m, SymMatrix):
            m = SymMatrix.from_rows(m)
        exprs.extend(m.entries())
    try:
        compiler()
    except CompilerError:
        return _interpreted(system, names, shapes, exprs)
    cnames = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                            system.inputs)
    body = function_source("jd_fn", exprs, cnames, whole, symmetric) + extra_source
    if lean and not extra_source and count_nodes(exprs, JIT_MAX_NODES + 1) <= JIT_MAX_NODES:
        jit = _jit(system, names, shapes, exprs, body)
        if jit is not None:
            return jit
    source = ("#define JD_LEAN 1\n" if lean else "") + HEADER + body
    return _load(system, names, shapes, source)  # the cached library when there is one


#: the largest lean function (nodes of its expression graph) compiled by LLVM in-process:
#: the energies of an 8-link spatial chain (3 500 nodes) take 47 ms at opt_level 0; larger
#: ones were not measured against the compiler, and stay C
JIT_MAX_NODES = 4000


def _jit(system: System, names: tuple[str, ...], shapes: tuple[tuple[int, int], ...],
         exprs: list[se.Basic], source: str) -> JitFunction | None:
    """``exprs`` compiled by SymEngine's LLVM backend (``opt_level=0``: the shortest compile;
    a lean function is evaluated once per sample), kept in ``<cache>/<key>.llvm`` under the
    hash of the generated C ``source``, pickled with its key and sealed
    (:mod:`jourdain.numeric.cachefile`: unpickled only when private, whole and of this key,
    else deleted and compiled again); None where this SymEngine has no LLVM backend or it
    cannot compile the expressions."""
    args = arguments(system)  # the C reads what it uses; the LLVM function takes all
    key = content_key("llvm", _GENERATOR_VERSION, se.__version__, source,
                      " ".join(map(str, args)))
    path = library_dir() / f"{key}.llvm"
    fn = load_pickle(path, key)
    if fn is None:
        try:
            fn = se.Lambdify(list(args), exprs, backend="llvm", cse=True, real=True,
                             opt_level=0)
        except (RuntimeError, ValueError, TypeError, NotImplementedError):
            return None
        try:
            keep_sealed(path, dump_pickle(key, fn))
        except Exception:  # noqa: BLE001 - one that cannot be pickled is compiled next time
            pass
    return JitFunction(names, shapes, args, key, system.f, len(system.parameters),
                       len(system.inputs), fn)


def library_key(source: str | tuple[str, ...],
                unit_flags: tuple[tuple[str, ...], ...] | None = None) -> str:
    """The cache key of the library that :func:`_load` builds from ``source``."""
    units = (source,) if isinstance(source, str) else source
    return content_key(_GENERATOR_VERSION, *units, *(" ".join(f) for f in unit_flags or ()))


def _load(system: System, names: tuple[str, ...], shapes: tuple[tuple[int, int], ...],
          source: str | tuple[str, ...], n_bodies: int = 0,
          unit_flags: tuple[tuple[str, ...], ...] | None = None,
          quick: bool = False) -> CompiledFunction:
    """Build (or load from the cache) the library of ``jd_fn`` and ``jd_fn_batch``
    (``unit_flags``: compiler flags per unit of ``source``). ``quick``: where that library is
    not at hand, the same source at -O0 under a key of its own, as a
    :class:`ProvisionalFunction` (the same numbers to the bit: no -O level reorders
    arithmetic, tests/test_native.py), for a first run while the library compiles."""
    key = library_key(source, unit_flags)
    kind: type[CompiledFunction] = CompiledFunction
    if quick and cached_library(key) is None:
        key, kind = content_key(_GENERATOR_VERSION, "-O0", key), ProvisionalFunction
        lib = build(key, source, extra_flags=("-O0",), unit_flags=unit_flags)
    else:
        lib = build(key, source, unit_flags=unit_flags)
    return _function(system, names, shapes, key, lib, n_bodies, kind)


def _function(system: System, names: tuple[str, ...], shapes: tuple[tuple[int, int], ...],
              key: str, lib: ctypes.CDLL, n_bodies: int = 0,
              kind: type[CompiledFunction] = CompiledFunction) -> CompiledFunction:
    """The function of the loaded library ``lib`` (its C signatures declared)."""
    vp = ctypes.c_void_p
    lib.jd_fn.restype = None
    lib.jd_fn.argtypes = [vp, vp, ctypes.c_double, vp, vp, vp]
    lib.jd_fn_batch.restype = None
    lib.jd_fn_batch.argtypes = [ctypes.c_long, ctypes.c_long, vp, vp, vp, vp, ctypes.c_long, vp,
                                ctypes.c_long, vp]
    if n_bodies:  # the recursion's engine: ÿ and the joint wrenches of a batch
        lib.jd_dynamics_batch.restype = ctypes.c_long
        lib.jd_dynamics_batch.argtypes = [ctypes.c_long, ctypes.c_long, vp, vp, vp, vp,
                                          ctypes.c_long, vp, ctypes.c_long, vp, vp]
    return kind(names, shapes, arguments(system), key, system.f, len(system.parameters),
                len(system.inputs), lib, n_bodies=n_bodies)


def _interpreted(system: System, names: tuple[str, ...], shapes: tuple[tuple[int, int], ...],
                 exprs: list[se.Basic]) -> InterpretedFunction:
    warnings.warn("no C compiler found: jourdain evaluates with SymEngine's Lambdify (slower); "
                  "install gcc or clang, or set CC", RuntimeWarning, stacklevel=3)
    args = arguments(system)
    try:
        fn = se.Lambdify(list(args), exprs, backend="llvm", cse=True, real=True)
    except (RuntimeError, ValueError):  # LLVM not in this SymEngine build
        fn = se.Lambdify(list(args), exprs, backend="lambda", cse=True, real=True)
    return InterpretedFunction(names, shapes, args, "", system.f, len(system.parameters),
                               len(system.inputs), fn)


def _recursive(system: System, full: bool, extra_source: str = "",
               directions: tuple | None = None, accel: bool = False,
               quick: bool = False) -> CompiledFunction:
    """Compile :func:`.recursive.recursive_source` (no symbolic M is formed)."""
    f, p = system.f, len(system.bodies)
    names: tuple[str, ...] = ("M", "k", "q")
    shapes: tuple[tuple[int, int], ...] = ((f, f), (f, 1), (f, 1))
    if full:
        names = ("M_bar", "J_bar", "q_c", "q_e", *names)
        shapes = ((6 * p, 6 * p), (6 * p, f), (6 * p, 1), (6 * p, 1), *shapes)
    if directions is not None:
        names = (*names, "Q_bar")
        shapes = (*shapes, (6 * p, sum(len(w) for w in directions)))
    try:
        compiler()
    except CompilerError:
        eom = projection(newton_euler(kinematics(system)))
        mats = {"M": eom.M, "k": eom.k, "q": eom.q}
        if full:
            ne = eom.newton_euler
            mats = {"M_bar": ne.M_bar, "J_bar": ne.J_bar, "q_c": ne.q_c, "q_e": ne.q_e, **mats}
        if directions is not None:
            mats["Q_bar"] = reactions(eom.newton_euler).Q_bar
        return lambdify(system, mats, extra_source)
    units = recursive_units(system, full, directions, extra_source,
                            accel_source(f) if accel else None)
    return _load(system, names, shapes, units, n_bodies=p, unit_flags=((), ENGINE_FLAGS),
                 quick=quick)


def _refuse_closed(system: System) -> None:
    """The tree's M, k, q of a closed system would leave its loops open: refused by name."""
    refuse_closed(system, "the compiled equations of the tree would leave the loops open",
                  "use the system's methods (evaluate, simulate, linearize), or system.tree "
                  "for the open tree")


@lru_cache(maxsize=32)
def _eom_function(system: System) -> CompiledFunction:
    """M̄, J̄, q̄^c, q̄^e, M, k, q and, where the joints' constrained directions can be formed,
    Q̄ (:func:`jourdain.stages.reactions.joint_directions`), compiled by the recursion."""
    _refuse_closed(system)
    try:
        directions = tuple(jr.wrenches for jr in joint_directions(system))
    except JourdainError:  # the equations of motion exist; the reactions report the reason
        directions = None
    return _recursive(system, full=True, directions=directions)


def build_eom_soon(system: System) -> None:
    """Start compiling the library of :func:`_eom_function` (M̄, J̄, q̄^c, q̄^e, M, k, q and Q̄ by
    the recursion: what ``System.evaluate`` and the reactions call) in a thread and return at
    once (:func:`jourdain.numeric.toolchain.build_soon`): for a caller that compiles other
    functions of the model meanwhile, such as ``jourdain run``, whose summary compiles the
    integrator's M, k, q, so that the two compilers run side by side. A later call of
    ``_eom_function`` waits for that build. Call it after any ``fork`` of this process."""
    build_soon(_eom_function, system, name="jourdain-eom-build")


#: the recursions' engine units: their loops over 3 and 6 components and over a joint's columns
#: peeled and unswitched (the per-state speed of -O3 for about a tenth of its extra compile
#: time: a 60-hinge tree 11.3 -> 9.6 µs, the build +0.03 s against +0.2 s at -O3); neither
#: reorders arithmetic, so the numbers are those of -O2
ENGINE_FLAGS = ("-fpeel-loops", "-funswitch-loops")


@lru_cache(maxsize=32)
def mkq_function(system: System) -> CompiledFunction:
    """Compiled ``M, k, q`` of the equations of motion for the integrator (memoized per system),
    with ``jd_accel`` (ÿ = M⁻¹(q − k)) when f ≤ ACCEL_MAX_F or every coordinate belongs to one
    joint: by the path of least predicted cost per right-hand side
    (:func:`jourdain.numeric.cost.evaluation_path`): the symbolic projection's straight-line
    code with LDLᵀ (:func:`symbolic_mkq`), the recursion in planar vectors
    (:func:`planar_function`) or in spatial vectors (:func:`dynamics_function`), each with its
    articulated-body ÿ where every coordinate belongs to one joint."""
    _refuse_closed(system)
    try:
        compiler()
    except CompilerError:  # evaluated without C: the recursion's fallback
        return dynamics_function(system)
    known = _recipe_key(system)
    fn = cached_mkq(system)
    if fn is not None:
        return fn
    choice = evaluation_path(system)
    if choice.path == "symbolic" and choice.eom is not None:
        parts = _symbolic_parts(system)  # the source that the first run read
        assert parts is not None
        names, shapes, source, _ = parts
        fn = _load(system, names, shapes, source)
    else:
        fn = (planar_function if choice.path == "planar" else dynamics_function)(system)
    if known is not None and type(fn) is CompiledFunction:
        keep_recipe(known, {"path": choice.path, "key": fn.key, "n_bodies": fn.n_bodies})
    return fn


@lru_cache(maxsize=32)
def _recipe_key(system: System) -> str | None:
    return recipe_key(system, "mkq_function", _GENERATOR_VERSION, ENGINE_FLAGS)


def cached_mkq(system: System) -> CompiledFunction | None:
    """:func:`mkq_function`'s library where a recipe of this very model names it and it is
    cached (:mod:`jourdain.numeric.recipes`): nothing derived, generated or compiled; else
    None."""
    known = _recipe_key(system)
    rec = load_recipe(known) if known is not None else None
    if (rec is None or not isinstance(rec.get("key"), str) or not rec["key"].isalnum()
            or type(rec.get("n_bodies")) is not int):
        return None
    lib = cached_library(rec["key"])
    if lib is None:
        return None
    f = system.f
    return _function(system, ("M", "k", "q"), ((f, f), (f, 1), (f, 1)), rec["key"], lib,
                     rec["n_bodies"])


def symbolic_mkq(system: System, eom: EquationsOfMotion) -> CompiledFunction:
    """``M, k, q`` of ``eom`` compiled with the integrator's ``jd_accel`` by LDLᵀ, as
    :func:`mkq_function` compiles them for small graphs: ``jd_fn`` in one function (never
    split: the graph is bounded, and the parts' shared array on the heap and their calls made
    every evaluation slower: n-link pendulum on a cart, n = 18, 1 481 nodes, 9.1 against 6.0
    ms per 10 s run), and ``jd_accel`` taking M's diagonal and upper triangle from
    ``jd_fn_upper`` (the solve reads no other entries; 1.5 % less time per run at n = 12)."""
    names, shapes, source = symbolic_source(system, eom)
    return _load(system, names, shapes, source)


@lru_cache(maxsize=32)
def _symbolic_parts(system: System) -> tuple | None:
    """:func:`~jourdain.numeric.symbolic_accel.symbolic_source` of the path that
    :func:`evaluation_path` chose, with its
    equations (None where it chose another path)."""
    choice = evaluation_path(system)
    if choice.path != "symbolic" or choice.eom is None:
        return None
    return (*symbolic_source(system, choice.eom), choice.eom)


@lru_cache(maxsize=32)
def dynamics_function(system: System, quick: bool = False) -> CompiledFunction:
    """Compiled recursion with ``M, k, q``, :meth:`CompiledFunction.dynamics` (ÿ and every
    joint wrench for a batch of states) and the integrator's ``jd_accel`` (articulated bodies
    where they apply, O(f), else LDLᵀ of M), memoized per system: one library serves
    :func:`mkq_function` where it takes the recursion."""
    _refuse_closed(system)
    return _recursive(system, full=False, accel=True, quick=quick)


@lru_cache(maxsize=32)
def planar_function(system: System, quick: bool = False) -> CompiledFunction:
    """Compiled ``M, k, q`` and the integrator's ``jd_accel`` of a planar system by the
    recursion in planar vectors (:mod:`jourdain.numeric.planar_recursion`; the caller checks
    :func:`~jourdain.numeric.planar_recursion.is_planar`), memoized per system."""
    _refuse_closed(system)
    f = system.f
    return _load(system, ("M", "k", "q"), ((f, f), (f, 1), (f, 1)),
                 recursion_units(system, planar=True), unit_flags=((), ENGINE_FLAGS),
                 quick=quick)


def recursion_units(system: System, planar: bool) -> tuple[str, str]:
    """The units of :func:`planar_function` (``planar``) or :func:`dynamics_function` (as
    :func:`_recursive` forms them with ``accel``): the generated per-joint code and the engine
    with the integrator's ``jd_accel``, which a first run on the engine sized at run time reads
    (:mod:`jourdain.numeric.runtime_engine`)."""
    if planar:
        local, engine, _ = planar_units(system, accel_source(system.f))
        return local, engine
    return recursive_units(system, accel_template=accel_source(system.f))


#: the memos of modules above this one that clear_cache empties too (they add themselves)
ALSO_CLEARED: list[Callable[[], None]] = []


def clear_cache(disk: bool = False) -> None:
    """Forget the compiled functions memoized in this process; with ``disk``, also delete the
    on-disk cache of compiled libraries (:func:`cache_dir`)."""
    _eom_function.cache_clear()
    mkq_function.cache_clear()
    _recipe_key.cache_clear()
    _symbolic_parts.cache_clear()
    for clear in ALSO_CLEARED:
        clear()
    dynamics_function.cache_clear()
    planar_function.cache_clear()
    evaluation_path.cache_clear()
    layout.cache_clear()
    plane_normal.cache_clear()
    if disk:
        d = cache_dir()
        if d.is_dir():
            for p in d.iterdir():
                if (p.suffix in (".so", ".c", ".llvm", ".recipe", ".target", ".sha256")
                        or p.name.endswith((".so.tmp", ".c.tmp"))):
                    p.unlink(missing_ok=True)
                elif p.is_dir() and (p.name.startswith(".build-") or p.name == "meshes"):
                    shutil.rmtree(p, ignore_errors=True)  # builds cut off; parsed meshes


