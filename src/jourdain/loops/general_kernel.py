"""The compiled right-hand side of a general system (velocity constraints): generated C for
the holonomic rows ``Φ, Φ_y, Φ_t`` (``jd_gpos``), every row's ``A, a`` (``jd_gvel``) and ``c``
(``jd_gacc``, the only one that needs ``ẏ``),
joined with the hand-written kernel of ``general_c.h`` (Newton on the dependent coordinates,
``W = [E_z; A]`` by LU, ``ẏ = L·z + l``, γ, ``M_z = LᵀM_tree·L`` by Cholesky), which calls the
tree's compiled ``M, k, q`` (:func:`jourdain.numeric.mkq_function`) through a function pointer.

It serves systems whose speeds are the rates of independent coordinates (the benchmark bicycle,
a rolling disc): jourdain's C integrator then integrates ``(y_i, ẏ_i)`` through its
``jd_accel`` hook, one C call per step loop (:func:`jourdain.loops.general_sim.simulate_general`);
the rates of the coordinates without a speed follow ``ẏ = L·z + l`` to the integrator's
accuracy, and every sample is taken back onto the rows (their residuals at rounding). Speeds
given by definition run the NumPy path (:class:`jourdain.loops.general.GeneralEvaluator`).
"""

from __future__ import annotations

import ctypes
from functools import lru_cache
from importlib import resources
from typing import Any

import numpy as np

from ..model import System
from ..numeric import mkq_function
from ..numeric.ccode import HEADER, argument_names, function_source
from ..numeric.toolchain import build, build_lock, content_key
from ..simulation.problem import address
from .general import GeneralEvaluator
from .general_choice import general_constraints

_VERSION = "general-c5"
REASONS = {1: "Newton found no configuration with the holonomic rows satisfied",
           2: "the velocity rows are singular or redundant with the speeds (W singular)",
           3: "M in the speeds is not positive definite"}


class _Gen(ctypes.Structure):
    _fields_ = [("tree", ctypes.c_void_p), ("p", ctypes.c_void_p), ("n", ctypes.c_long),
                ("ni", ctypes.c_long), ("g", ctypes.c_long), ("mh", ctypes.c_long),
                ("mv", ctypes.c_long), ("rh", ctypes.c_long), ("ind", ctypes.c_void_p),
                ("dep", ctypes.c_void_p), ("rows_h", ctypes.c_void_p),
                ("rows_v", ctypes.c_void_p), ("spd", ctypes.c_void_p), ("y", ctypes.c_void_p),
                ("work", ctypes.c_void_p), ("piv", ctypes.c_void_p), ("info", ctypes.c_void_p),
                ("newton_tol", ctypes.c_double), ("max_newton", ctypes.c_long)]


def general_source(system: System) -> str:
    """The C source of ``system``'s kernel: ``jd_gpos``, ``jd_gvel``, ``jd_gacc``, then
    ``dense_c.h`` and ``general_c.h``."""
    tree = system.tree
    con = general_constraints(system)
    names = argument_names(tree.y, tree.yd, tree.t, tree.parameter_symbols, tree.inputs)
    kernel = (resources.files(__package__) / "dense_c.h").read_text() + (
        resources.files(__package__) / "general_c.h").read_text()
    return (HEADER + function_source("jd_gpos", [*con.Phi.entries(), *con.Phi_y.entries(),
                                                 *con.Phi_t.entries()], names)
            + function_source("jd_gvel", [*con.A.entries(), *con.a.entries()], names)
            + function_source("jd_gacc", con.c.entries(), names) + kernel)


def general_library(system: System) -> ctypes.CDLL:
    """The compiled kernel of ``system`` (cached by content)."""
    with build_lock("general library"):
        return _general_library(system)


@lru_cache(maxsize=16)
def _general_library(system: System) -> ctypes.CDLL:
    source = general_source(system)
    lib = build(content_key(_VERSION, source), source, ("-O2",))
    vp, lg = ctypes.c_void_p, ctypes.c_long
    lib.jd_gen_work.restype = lg
    lib.jd_gen_work.argtypes = [lg, lg, lg, lg]
    lib.jd_gen_samples.restype = lg
    lib.jd_gen_samples.argtypes = [vp, lg, vp, vp, lg, vp, vp, vp]
    return lib


def supported(ev: GeneralEvaluator) -> bool:
    """Whether the kernel serves ``ev``'s partition: speeds that are rates of independent
    coordinates."""
    sc = ev.choice.speed_coordinates
    return sc is not None and set(sc) <= set(ev.choice.independent)


class GeneralKernel:
    """The C-side state of one evaluator's partition (a ``jd_gen`` struct)."""

    def __init__(self, ev: GeneralEvaluator) -> None:
        if not supported(ev):
            raise ValueError("the C kernel needs speeds that are rates of independent "
                             "coordinates")
        system = ev.system
        self.ev = ev
        self.lib = general_library(system)
        self.tree = mkq_function(system.tree)
        con = general_constraints(system)
        ch = ev.choice
        n, g = ev.n, len(ch.speeds)
        self.n, self.g, self.mh, self.mv = n, g, con.Phi.shape[0], con.A.shape[0]
        self.ni = len(ch.independent)
        self.ind = np.array(ch.independent, dtype=np.int_)
        self.dep = np.array(ch.dependent or (0,), dtype=np.int_)
        self.rows_h = np.array(ch.rows_h or (0,), dtype=np.int_)
        self.rows_v = np.array(ch.rows_v or (0,), dtype=np.int_)
        self.spd = np.array(ch.speed_coordinates, dtype=np.int_)
        self.y = np.real(ev.y_guess).astype(float).copy()
        self.work = np.zeros(int(self.lib.jd_gen_work(n, self.mh, self.mv, g)) + 16)
        self.piv = np.zeros(n, dtype=np.int_)
        self.info = np.zeros(4)
        s = self.struct = _Gen()
        s.tree, s.p = self.tree.address, address(ev.p)
        s.n, s.ni, s.g, s.mh, s.mv, s.rh = n, self.ni, g, self.mh, self.mv, len(ch.dependent)
        s.ind, s.dep, s.rows_h = address(self.ind), address(self.dep), address(self.rows_h)
        s.rows_v, s.spd, s.y = address(self.rows_v), address(self.spd), address(self.y)
        s.work, s.piv, s.info = address(self.work), address(self.piv), address(self.info)
        s.newton_tol, s.max_newton = ev.newton_tol, ev.max_newton

    @property
    def accel_address(self) -> int:
        return int(ctypes.cast(self.lib.jd_gen_accel, ctypes.c_void_p).value or 0)

    @property
    def state_address(self) -> int:
        return ctypes.addressof(self.struct)

    def reason(self) -> str:
        return REASONS.get(int(self.info[1]), "")

    def samples(self, t: np.ndarray, x: np.ndarray) -> tuple[dict[str, np.ndarray], int]:
        """States ``x`` (N × ≥2·n_i: y_i, ẏ_i) at ``t``: ``y, yd, ydd, r`` (the tree's residual
        ``M·ÿ + k − q``), ``Phi``, ``Phi_dot`` (every row's ``A·ẏ + a``), ``lam`` (the
        multipliers where every row is independent, else NaN), N rows each, and the index of
        the first that failed (-1: none; NaN from there)."""
        n, mh, mv = self.n, self.mh, self.mv
        t = np.ascontiguousarray(t, dtype=float)
        x = np.ascontiguousarray(x, dtype=float)
        N, w = t.size, 4 * n + mh + 2 * mv
        out = np.full((N, w), np.nan)
        scratch = np.zeros(max(mv * mv, 1))
        bad = int(self.lib.jd_gen_samples(self.state_address, N, address(t), address(x),
                                          x.shape[1], address(self.ev.u), address(out),
                                          address(scratch)))
        if bad >= 0:
            out[bad:] = np.nan
        cols = {"y": (0, n), "yd": (n, 2 * n), "ydd": (2 * n, 3 * n), "r": (3 * n, 4 * n),
                "Phi": (4 * n, 4 * n + mh), "Phi_dot": (4 * n + mh, 4 * n + mh + mv),
                "lam": (4 * n + mh + mv, w)}
        return {k: out[:, a:b] for k, (a, b) in cols.items()}, bad

    def __getstate__(self) -> Any:  # ctypes structures do not pickle
        raise TypeError("GeneralKernel holds C pointers and cannot be pickled")


__all__ = ["GeneralKernel", "general_library", "general_source", "supported"]
