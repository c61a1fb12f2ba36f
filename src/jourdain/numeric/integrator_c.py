"""C source of jourdain's integrators for ``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t)``.

The step loop runs in C: Dormand–Prince 5(4) ("RK45") and 8(5,3) ("DOP853") with adaptive
steps and PI step-size control (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4–II.6, II.10;
Gustafsson's controller, *Solving ODEs II*, §IV.2), and the implicit Radau IIA method of order 5
for stiff problems (Hairer & Wanner, *Solving ODEs II*, §IV.8: simplified Newton iterations in
the eigenbasis of the Runge–Kutta matrix, a forward-difference Jacobian, the embedded error
estimate and Gustafsson's step-size predictor), their continuous extensions for output at
requested times and for locating events, and ``ÿ = M⁻¹(q − k)`` in every right-hand side (the
model library's ``jd_accel``, else an LDLᵀ here). The state is ``x = [y, ẏ, W]`` with ``W`` the
work of the generalized applied forces ``q`` (``Ẇ = ẏᵀq``), integrated to the same tolerance,
for the energy balance.

The source is six files beside this module, joined into two translation units by
:func:`units`: ``rk_tables.h`` (the coefficients, cited there), ``integrator_rhs.h`` (problem,
inputs, right-hand side), ``integrator_output.h`` (continuous extensions, events, output),
``integrator_radau.h`` (Radau IIA) and ``integrator_explicit.h`` (the explicit step loop and the
entry points ``jd_integrate`` and ``jd_rhs``) make the first, compiled at -O2;
``integrator_kernels.h`` (the loops over the state vector of every step and Radau's LU) is
the second, compiled at -O3, and is declared in the first (after the tables, before the
right-hand side, which checks states with its ``all_finite``). Compiling it all as one unit at
-O3 took 1.3-1.6 s (a machine's first simulation, and its first ``jourdain run``, waits for
it), the two units 0.34 s and 0.30 s in parallel, with the same time per run and the same
numbers to the bit (``integrator_kernels.h`` says what was measured, and what the step loop
costs beside the right-hand side: 48-53 % of one at n = 11, from 69-74 %). The library with
the stage sums in vector tiles (2026-11-27) compiles in 0.78 s against 0.76 s before (best of
4 each, alternated, a loaded 2-core machine, the prebuilt library's -march=native).

**Own step loop, not a maintained library — the decision and its measurement.** A maintained
integrator would be preferable where it is as fast. The candidates that Python reaches are
SciPy's ``solve_ivp`` and SUNDIALS CVODE (through scikit-sundae); both call the right-hand side
through Python, which costs more than the right-hand side itself (a ctypes call from Python is
about 1 µs, the right-hand side of the 4-link pendulum on a cart 0.1–0.2 µs), and neither takes
a C function pointer. ``benchmarks/integrators.py`` runs the same compiled
right-hand side under each, each at the loosest tolerance whose final state is as accurate as
the C loop's at rtol = atol = 1e-8 (n-link pendulum on a cart, 10 s). Measured (2-core AMD EPYC,
loaded machine, best of 5 rounds; scikit-sundae 1.2.0, SciPy 1.17.1): at n = 4 the C loop
1.15 ms (3 170 evaluations), SciPy's DOP853 102× and LSODA 20× slower, CVODE (Adams) 66×
slower (3 345 evaluations: the same work, the time is the Python call per evaluation); at
n = 12 the C loop 7.8 ms, DOP853 15×, LSODA 6.6×, CVODE 11× slower. CVODE's own loop in C
with a C right-hand side would need SUNDIALS built and linked by jourdain's toolchain, a
dependency the compile-at-first-use design avoids; the own loop is some 900 lines of C, checked
against the coefficients' order conditions (tests/test_integrator_tables.py) and against SciPy's
integrators and closed-form motions (tests/test_simulate.py).
"""

from __future__ import annotations

import ctypes
import re
from fractions import Fraction
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

from . import toolchain

if TYPE_CHECKING:  # imported where used: setup.py builds the library without NumPy
    import numpy as np

#: the translation units of the library: the line that opens each (the kernels' unit defines
#: JD_KERNELS: their definitions; elsewhere their declarations), its files in order, and its
#: compiler flags after :data:`jourdain.numeric.toolchain.CFLAGS` (see the module docstring)
UNITS: tuple[tuple[str, tuple[str, ...], tuple[str, ...]], ...] = (
    ("", ("rk_tables.h", "integrator_kernels.h", "integrator_rhs.h", "integrator_output.h",
          "integrator_radau.h", "integrator_explicit.h"), ()),
    ("#define JD_KERNELS 1\n", ("integrator_kernels.h",), ("-O3",)),
    # the interpreter of generated code, with the generated code's inline functions and its
    # solve's loop (ldl_solve.h) taking the size as a parameter
    ("#define JD_SOLVE_N_PARAM const long jd_n_,\n#define JD_F jd_n_\n"
     "#define jd_solve_mkq jd_solve_loop\n",
     ("jd_inline.h", "sincos.h", "ldl_solve.h", "interpreter.h"), ()),
    # the recursions' engines sized at run time, planar and spatial (runtime_head.h: their
    # jd_local on the interpreter above, numeric/runtime_engine.py); at -O1, which reorders no
    # arithmetic either: where the library is not prebuilt, they add 0.25-0.35 s to its build
    # (0.6 s at -O2; 0.65-0.9 s without them; 2-core AMD EPYC, 2026-11-27), and their first
    # runs take 1.3-2 times the model library's time per state at either level
    ("#define JD_RT_PLANAR 1\n", ("runtime_head.h", "planar_engine.h", "runtime_engine.h"),
     ("-O1",)),
    ("#define JD_RT_PLANAR 0\n", ("runtime_head.h", "recursive_engine.h", "runtime_engine.h"),
     ("-O1",)),
)

_TABLE = re.compile(r"static const double (\w+)(?:\[\d+\])? = \{?([^};]*)\}?;")
_COMMENT = re.compile(r"/\*.*?\*/", re.S)


def _read(name: str) -> str:
    return (resources.files(__package__) / name).read_text()


def tables() -> str:
    """The C constants of the methods' coefficients (``rk_tables.h``: the published tables,
    cited there, exact quotients where they are rational)."""
    return _read("rk_tables.h")


def _entries(text: str | None) -> dict[str, list[str]]:
    body = _COMMENT.sub("", tables() if text is None else text)
    return {m.group(1): [v.strip() for v in m.group(2).split(",") if v.strip()]
            for m in _TABLE.finditer(body)}


def _number(entry: str) -> float:
    """An entry as the C compiler reads it: a decimal, or a quotient of two (correctly rounded
    once, as IEEE division of exact operands is)."""
    num, _, den = entry.partition("/")
    return float(num) / float(den) if den else float(num)


def table_values(text: str | None = None) -> dict[str, np.ndarray]:
    """The arrays of :func:`tables` by name, as doubles."""
    import numpy as np

    return {k: np.array([_number(v) for v in vals]) for k, vals in _entries(text).items()}


def table_fractions(text: str | None = None) -> dict[str, list[Fraction | None]]:
    """The arrays of :func:`tables` by name as exact rationals: entries written as quotients or
    whole numbers; None for entries written as decimals (irrational coefficients)."""
    out: dict[str, list[Fraction | None]] = {}
    for k, vals in _entries(text).items():
        row: list[Fraction | None] = []
        for v in vals:
            num, _, den = v.partition("/")
            if den:
                row.append(Fraction(num.strip()) / Fraction(den.strip()))
            elif float(v).is_integer():
                row.append(Fraction(int(float(v))))
            else:
                row.append(None)
        out[k] = row
    return out


def units() -> tuple[tuple[str, tuple[str, ...]], ...]:
    """The C source of the integrator library: each translation unit's text and flags."""
    return tuple((head + "\n".join(_read(n) for n in files), flags)
                 for head, files, flags in UNITS)


def library_source() -> tuple[str, list[str], list[tuple[str, ...]]]:
    """The library's content key (:func:`jourdain.numeric.toolchain.content_key`: the units'
    text and flags, the compiler's flags and target), its units' text and their flags."""
    us = units()
    texts, flags = [text for text, _ in us], [fl for _, fl in us]
    return toolchain.content_key("integrator", *texts, *(" ".join(f) for f in flags)), texts, flags


def prebuild(dest: Path) -> Path:
    """Compile the library into ``dest`` at install time (``setup.py``): found there by
    :func:`integrator_library` on a machine's first run, as long as
    its key matches (:func:`jourdain.numeric.toolchain.prebuild`)."""
    key, texts, flags = library_source()
    return toolchain.prebuild(dest, key, texts, flags)


@lru_cache(maxsize=1)
def integrator_library() -> ctypes.CDLL:
    """The compiled integrator (built once, cached on disk like the model code, or prebuilt):
    its translation units (:data:`UNITS`: the step loops at -O2, the kernels at -O3, the
    interpreter of generated code, the recursions sized at run time), its entry points
    typed."""
    key, texts, flags = library_source()
    lib = toolchain.build(key, texts, unit_flags=flags)
    vp, lg, db = ctypes.c_void_p, ctypes.c_long, ctypes.c_double
    lib.jd_integrate.restype = ctypes.c_int
    lib.jd_integrate.argtypes = [vp, db, vp, vp, vp, vp, vp, vp, lg, vp, vp, vp, vp, lg, vp, vp,
                                 vp, vp, lg, vp, lg, vp]
    lib.jd_rhs.restype = ctypes.c_int
    lib.jd_rhs.argtypes = [vp, db, vp, vp, vp]
    lib.jd_interp_fn.restype = None
    lib.jd_interp_fn.argtypes = [vp, vp, vp, db, vp, vp, vp]
    lib.jd_interp_batch.restype = None
    lib.jd_interp_batch.argtypes = [vp, lg, lg, vp, vp, vp, vp, lg, vp, lg, vp]
    for engine in ("plane", "spatial"):  # the recursions sized at run time (runtime_engine.h)
        fn, batch = getattr(lib, f"jd_rt_{engine}_fn"), getattr(lib, f"jd_rt_{engine}_batch")
        fn.restype, batch.restype = None, None
        fn.argtypes = [vp, vp, vp, db, vp, vp, vp]
        batch.argtypes = [vp, lg, lg, vp, vp, vp, vp, lg, vp, lg, vp]
    return lib
