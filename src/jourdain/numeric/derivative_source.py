"""C source of the first derivatives of a tree's dynamics (:mod:`.derivatives`): the tables
of ``derivative_engine.h`` and the generated local expressions with their derivatives.

The engine runs the recursion of :mod:`.recursive` in forward mode. Each body's quantities
carry their derivatives with respect to the variables they depend on, in two blocks, the
coordinates ``y`` and the rates and inputs ``(ẏ, u)``; a body's variables are its parent's in
the same order followed by the new ones its local expressions bring in (its joint's motion and
columns, its applied force and torque, the rates of its columns). So a parent's derivatives are
a prefix of its child's, and the work per body is proportional to the number of variables on
its path: O(Σ_b depth_b), as the recursive derivatives of Carpentier and Mansard (2018).

The local expressions and their nonzero first derivatives are symbolic (the forward mode over
their shared graph, :func:`jourdain.graph.jet`) and compiled with the graph CSE of
:mod:`.ccode`; ``jdd_pd_dst`` puts each derivative in its place in the engine's work array.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from typing import TYPE_CHECKING

import symengine as se

from ..errors import ModelError
from ..graph import jet
from .ccode import HEADER, argument_names, function_source
from .recursive import BODY_BLOCK, COLUMN_BLOCK, c_table, layout

if TYPE_CHECKING:
    from ..model.system import System

#: the quantities of a body in the engine's order (enum of derivative_engine.h): rows, and
#: whether they depend on the rates and inputs (position quantities do not)
QUANTITIES: tuple[tuple[str, int, bool], ...] = (
    ("R", 9, False), ("O", 3, False), ("W", 3, True), ("V", 3, True), ("AL", 3, True),
    ("A", 3, True), ("P", 6, False), ("CC", 3, False), ("WC", 6, True),
    ("PARTS", BODY_BLOCK, True), ("COLS", 0, True), ("VCOLS", 0, False))
#: rows of the body's local expressions that are positions: the joint's A and d (no rates)
POSITION_ROWS = range(12)
#: rows of the mass data: m, com, inertia (parameters only)
MASS_ROWS = range(24, 34)

ENGINE = resources.files(__package__ or "jourdain.numeric").joinpath(
    "derivative_engine.h").read_text(encoding="utf-8")
ENTRY = resources.files(__package__ or "jourdain.numeric").joinpath(
    "derivative_entry.h").read_text(encoding="utf-8")


@dataclass(frozen=True)
class DerivativeLayout:
    """The variables of every body (positions in the coordinate block and in the block of
    rates and inputs: ẏ_j is j, u_k is f + k) and the source's sizes."""

    vars_y: tuple[tuple[int, ...], ...]
    vars_v: tuple[tuple[int, ...], ...]
    source: str


#: the groups of a body's local expressions (first row, rows): A, d, ω̄, v̄, ᾱ, ā, m, com, I,
#: f, l; a column's J_R and J_T
PART_GROUPS = ((0, 9), (9, 3), (12, 3), (15, 3), (18, 3), (21, 3), (24, 1), (25, 3), (28, 6),
               (34, 3), (37, 3))


def _group(q: str, r: int) -> tuple[int, int]:
    """The group (first row, rows) of row r of a body's local expressions (q "PARTS") or of
    its columns ("COLS")."""
    if q == "COLS":
        return r - r % 3, 3
    return next(g for g in PART_GROUPS if g[0] <= r < g[0] + g[1])


def derivative_layout(system: System) -> DerivativeLayout:
    """The variables of every body, and the C of the derivative unit (tables, generated local
    expressions with their derivatives, the engine)."""
    lay = layout(system)
    f, nu, p = system.f, len(system.inputs), len(lay.parent)
    variables = (*system.y, *system.yd, *system.inputs)
    exprs = list(lay.exprs)
    j = jet(exprs, variables, {})
    n_local = len(exprs)
    col_start = [0]
    for c in lay.columns:
        col_start.append(col_start[-1] + len(c))
    col_body = [b for b, cs in enumerate(lay.columns) for _ in cs]

    def where(e: int) -> tuple[int, str, int]:
        """(body, quantity, row) of local expression e."""
        if e < BODY_BLOCK * p:
            return e // BODY_BLOCK, "PARTS", e % BODY_BLOCK
        c, r = divmod(e - BODY_BLOCK * p, COLUMN_BLOCK)
        b = col_body[c]
        return b, "COLS", COLUMN_BLOCK * (c - col_start[b]) + r

    # the variables each body's local expressions bring in
    own_y: list[set[int]] = [set() for _ in range(p)]
    own_v: list[set[int]] = [set() for _ in range(p)]
    for e, grad in enumerate(j.gradients):
        b, q, r = where(e)
        for x in grad:
            position = q == "COLS" or r in POSITION_ROWS
            if x >= f and position:
                raise ModelError(f"body {system.bodies[b].name!r}: its joint's position or "
                                 "axes depend on rates or inputs; derivatives need positions "
                                 "that depend on coordinates and time only")
            if q == "PARTS" and r in MASS_ROWS:
                raise ModelError(f"body {system.bodies[b].name!r}: its mass data depend on "
                                 "the state; derivatives need mass data of parameters only")
            (own_y if x < f else own_v)[b].add(x if x < f else x - f)
    for b, cs in enumerate(lay.columns):
        own_v[b].update(cs)
    vars_y: list[tuple[int, ...]] = []
    vars_v: list[tuple[int, ...]] = []
    for b in range(p):
        lam = lay.parent[b]
        py = vars_y[lam] if lam >= 0 else ()
        pv = vars_v[lam] if lam >= 0 else ()
        vars_y.append(py + tuple(sorted(own_y[b] - set(py))))
        vars_v.append(pv + tuple(sorted(own_v[b] - set(pv))))

    # the work arrays: values (X) and tangents (D), per body and quantity
    nq = len(QUANTITIES)
    val_off: list[int] = []
    tan_off: list[int] = []
    n_val = 0
    n_tan = 0
    pos = {}
    # stored values: R 9, O 3, W 3, V 3, AL 3, A 3, P 6, CC 3, WC 6 per body, 6 per column
    n_values = 39 * p + COLUMN_BLOCK * len(col_body)
    for b in range(p):
        ny, nv = len(vars_y[b]), len(vars_v[b])
        nc = len(lay.columns[b])
        for name, rows, rates in QUANTITIES:
            if name == "COLS":
                rows, value = COLUMN_BLOCK * nc, n_values + BODY_BLOCK * p + 6 * col_start[b]
            elif name == "PARTS":
                value = n_values + BODY_BLOCK * b
            else:
                rows = COLUMN_BLOCK * nc if name == "VCOLS" else rows
                value = n_val
                n_val += rows
            val_off.append(value)
            o0 = n_tan
            n_tan += rows * ny
            o1 = -1
            if rates:
                o1 = n_tan
                n_tan += rows * nv
            tan_off.extend((o0, o1))
            pos[(b, name)] = (o0, o1, ny, nv)
    assert n_val == n_values

    # the nonzero derivatives of the local expressions, and where each goes
    index_y = [{x: k for k, x in enumerate(vy)} for vy in vars_y]
    index_v = [{x: k for k, x in enumerate(vv)} for vv in vars_v]
    partials: list[se.Basic] = []
    dst: list[int] = []
    for e, grad in enumerate(j.gradients):
        b, q, r = where(e)
        o0, o1, ny, nv = pos[(b, q)]
        for x in sorted(grad):
            if x < f:
                dst.append(o0 + r * ny + index_y[b][x])
            else:
                dst.append(o1 + r * nv + index_v[b][x - f])
            partials.append(grad[x])
    # the groups of local expressions with a nonzero derivative in a block ("live"): the
    # engine reads the others as constants (no tangent) and zeroes only these before the
    # derivatives are put in place
    live: set[tuple[int, str, int, int]] = set()
    for e, grad in enumerate(j.gradients):
        b, q, r = where(e)
        row0, _ = _group(q, r)
        for x in grad:
            live.add((b, q, row0, 0 if x < f else 1))
    live_flags: list[int] = []
    zero_off: list[int] = []
    zero_len: list[int] = []
    for b in range(p):
        for q, rows in (("PARTS", BODY_BLOCK), ("COLS", COLUMN_BLOCK * len(lay.columns[b]))):
            o0, o1, ny, nv = pos[(b, q)]
            for r in range(rows):
                row0, n_rows = _group(q, r)
                flags = sum(1 << blk for blk in (0, 1) if (b, q, row0, blk) in live)
                live_flags.append(flags)
                if r == row0:
                    for blk, (o, n) in enumerate(((o0, ny), (o1, nv))):
                        if flags >> blk & 1:
                            zero_off.append(o + row0 * n)
                            zero_len.append(n_rows * n)
    live_start = [0]
    for b in range(p):
        live_start.append(live_start[-1] + BODY_BLOCK + COLUMN_BLOCK * len(lay.columns[b]))
    col_rate = [index_v[col_body[c]][coord] for c, coord in
                enumerate(k for cs in lay.columns for k in cs)]
    flat_y = [x for vy in vars_y for x in vy]
    flat_v = [x for vv in vars_v for x in vv]
    starts_y = [0]
    starts_v = [0]
    for vy, vv in zip(vars_y, vars_v, strict=True):
        starts_y.append(starts_y[-1] + len(vy))
        starts_v.append(starts_v[-1] + len(vv))
    scratch = 12 * 3 * max((len(a) + len(b) for a, b in zip(vars_y, vars_v, strict=True)),
                           default=1)
    names = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                           system.inputs)
    parts = function_source("jdd_parts", [*exprs, *partials], names)
    head = (f"#define JDD_P {p}\n#define JDD_F {f}\n#define JDD_NU {nu}\n"
            f"#define JDD_NL {n_local}\n#define JDD_NPD {len(partials)}\n"
            f"#define JDD_NVAL {n_values}\n#define JDD_NX {n_values + n_local + len(partials)}\n"
            f"#define JDD_NTAN {max(n_tan, 1)}\n#define JDD_SCRATCH {max(scratch, 1)}\n"
            f"#if {nq} != 12\n#error quantities\n#endif\n"
            + c_table("jdd_parent", list(lay.parent))
            + c_table("jdd_col_start", col_start)
            + c_table("jdd_col_coord", [k for cs in lay.columns for k in cs])
            + c_table("jdd_col_rate", col_rate)
            + c_table("jdd_ny", [len(v) for v in vars_y])
            + c_table("jdd_nv", [len(v) for v in vars_v])
            + c_table("jdd_vars_y", flat_y) + c_table("jdd_vars_y_start", starts_y)
            + c_table("jdd_vars_v", flat_v) + c_table("jdd_vars_v_start", starts_v)
            + c_table("jdd_val", val_off) + c_table("jdd_off", tan_off)
            + c_table("jdd_pd_dst", dst, "long")
            + f"#define JDD_NZERO {len(zero_off)}\n"
            + c_table("jdd_zero_off", zero_off, "long") + c_table("jdd_zero_len", zero_len)
            + c_table("jdd_live", live_flags) + c_table("jdd_live_start", live_start))
    source = HEADER + parts + head + ENGINE + ENTRY
    return DerivativeLayout(tuple(vars_y), tuple(vars_v), source)
