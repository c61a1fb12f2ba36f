"""The generated C of an FMU besides the model's own code: the model identifier, the start
values, the reaction outputs' tables and ``model.h``.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

from ...analysis.reactions import check_reactions
from ...errors import EvaluationError, JourdainError, ModelError
from ...model.system import System
from ...stages.reactions import joint_directions
from .description import Layout

_C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if "
    "inline int long register restrict return short signed sizeof static struct switch typedef "
    "union unsigned void volatile while".split())


def model_identifier_of(name: str) -> str:
    """A C identifier from a model's name (``"double pendulum"`` -> ``double_pendulum``)."""
    ident = re.sub(r"[^A-Za-z0-9_]+", "_", name).strip("_") or "model"
    if ident[0].isdigit() or ident in _C_KEYWORDS or ident.startswith("fmi2"):
        ident = "jd_" + ident
    return ident[:64]


def _state(system: System, values: Any, what: str, suffix: str) -> list[float]:
    """Initial coordinates or rates by name (a mapping) or in order (a sequence)."""
    f, names = system.f, system.coordinate_names
    if values is None:
        return [0.0] * f
    if isinstance(values, Mapping):
        out = [0.0] * f
        for k, v in values.items():
            key = str(k)
            if suffix and key.endswith(suffix) and key[:-len(suffix)] in names:
                key = key[:-len(suffix)]
            if key not in names:
                raise EvaluationError(f"{what}: {k!r} is not a coordinate; coordinates are "
                                      f"{', '.join(names)}")
            out[names.index(key)] = _finite(v, f"{what} {k}")
        return out
    seq = list(values)
    if len(seq) != f:
        raise EvaluationError(f"{what}: expected {f} values ({', '.join(names)}), got {len(seq)}")
    return [_finite(v, f"{what}[{i}]") for i, v in enumerate(seq)]


def _finite(v: Any, what: str) -> float:
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise EvaluationError(f"{what}: expected a number, got {v!r}") from None
    if not math.isfinite(x):
        raise EvaluationError(f"{what} = {v!r} is not finite")
    return x


def _reaction_names(system: System, reactions: Sequence[str] | str | None
                    ) -> tuple[list[Any], list[str]]:
    """The joints with their constrained directions, and the chosen components by name."""
    if reactions is None or (not isinstance(reactions, str) and not list(reactions)):
        return [], []
    try:
        joints = list(joint_directions(system))
        check_reactions(system)
    except JourdainError as exc:
        raise ModelError(f"the reaction forces of {system.name!r} cannot be exported: {exc}"
                         ) from None
    names = [n for jr in joints for n in jr.names]
    if isinstance(reactions, str):
        if reactions != "all":
            raise ModelError(f'reactions: expected "all" or a list of names such as '
                             f'{names[:2]}, got {reactions!r}')
        return joints, names
    chosen: list[str] = []
    for r in reactions:
        if r not in names:
            close = difflib.get_close_matches(str(r), names, n=1)
            hint = f' (did you mean "{close[0]}"?)' if close else ""
            raise ModelError(f'reactions: "{r}" is not a reaction component of '
                             f"{system.name!r}{hint}; they are: {', '.join(names)}")
        if r not in chosen:
            chosen.append(r)
    return joints, chosen


def _tables(joints: list[Any], chosen: list[str], bodies: list[str]) -> tuple[str, list[Any]]:
    """model.h's tables of the reaction outputs and the direction expressions of jd_dirs."""
    if not chosen:
        return "", []
    used = [jr for jr in joints if any(n in chosen for n in jr.names)]
    body, ndir, off, exprs = [], [], [0], []
    for jr in used:
        body.append(bodies.index(jr.child))
        ndir.append(len(jr.wrenches))
        for w in jr.wrenches:
            exprs.extend(w)
        off.append(off[-1] + 6 * len(jr.wrenches))
    g_joint, g_dir = [], []
    for n in chosen:
        j = next(k for k, jr in enumerate(used) if n in jr.names)
        g_joint.append(j)
        g_dir.append(used[j].names.index(n))
    text = (f"#define JD_NJ {len(used)}\n#define JD_NE {max(off[-1], 1)}\n"
            + _array("int", "jd_rj_body", body) + _array("int", "jd_rj_ndir", ndir)
            + _array("int", "jd_rj_off", off) + _array("int", "jd_g_joint", g_joint)
            + _array("int", "jd_g_dir", g_dir)
            + "void jd_dirs(const double *y, const double *yd, double t, const double *p,\n"
              "             const double *u, double *out);\n")
    return text, exprs


def _array(ctype: str, name: str, values: Sequence[Any]) -> str:
    body = ", ".join(repr(float(v)) if ctype == "double" else str(int(v)) for v in values)
    return f"static const {ctype} {name}[{max(len(values), 1)}] = {{{body or '0'}}};\n"


def _closed_header(n: int, m: int, independent: Sequence[int], dependent: Sequence[int],
                   rows: Sequence[int], z_start: Sequence[float], newton_tol: float,
                   max_newton: int, cond_limit: float) -> str:
    """model.h's part for a closed system: the partition fixed at export, Newton's start
    (the assembled configuration) and the kernel's settings (closed.c)."""
    return (f"#define JD_CLOSED 1\n#define JD_NZ {n}\n#define JD_NDEP {len(dependent)}\n"
            f"#define JD_NPHI {m}\n#define JD_NEWTON_TOL {float(newton_tol)!r}\n"
            f"#define JD_MAX_NEWTON {int(max_newton)}\n#define JD_COND_LIMIT {float(cond_limit)!r}\n"
            + _array("long", "jd_ind", independent) + _array("long", "jd_dep", dependent)
            + _array("long", "jd_rows", rows) + _array("double", "jd_z_start", z_start)
            + "long jd_closed_work(void);\n"
              "int jd_closed_dynamics(double *z, double *y_last, double *info, double *work,\n"
              "                       long *piv, const double *y, const double *yd, double t,\n"
              "                       const double *p, const double *u, double *ydd,\n"
              "                       double *out);\n")


def _model_header(lay: Layout, guid: str, tolerance: float, n_bodies: int, tables: str,
                  closed: str = "") -> str:
    vs = lay.variables
    f = lay.f
    x_start = [v.start for v in vs[1:1 + 2 * f]]
    p_start = [v.start for v in vs[1 + 4 * f:1 + 4 * f + lay.n_p]]
    u_start = [v.start for v in vs[1 + 4 * f + lay.n_p:1 + 4 * f + lay.n_p + lay.n_u]]
    return ("/* generated by jourdain; do not edit: sizes, start values and tables of the FMU */\n"
            "#ifndef JD_MODEL_H\n#define JD_MODEL_H\n"
            f'#define JD_GUID "{guid}"\n'
            f"#define JD_NY {f}\n#define JD_NP {lay.n_p}\n#define JD_NU {lay.n_u}\n"
            f"#define JD_NG {len(lay.reactions)}\n#define JD_NB {n_bodies}\n"
            f"#define JD_NOUT {lay.n_out}\n"
            f"#define JD_DEFAULT_TOLERANCE {tolerance!r}\n"
            + _array("double", "jd_x_start", x_start)
            + _array("double", "jd_p_start", p_start)
            + _array("double", "jd_u_start", u_start)
            + "int jd_dynamics(const double *y, const double *yd, double t, const double *p,\n"
              "                const double *u, double *ydd, double *wrench);\n"
            + tables + closed + "#endif\n")


