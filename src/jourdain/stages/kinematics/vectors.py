"""3-vectors and 3×3 matrices as tuples of SymEngine expressions: the small helpers the stages
compute with (sums, products, cross and dot products), and their conversions to and from
:class:`~jourdain.symbolic.SymMatrix`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import symengine as se

from ...model.joints import Mat3, Vec3
from ...symbolic import SymMatrix

if TYPE_CHECKING:
    pass


ZERO = se.Integer(0)
Z3: Vec3 = (ZERO, ZERO, ZERO)


# --- small vector helpers on 3-tuples of SymEngine expressions ---------------------------------
def _add(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _scale(a: Vec3, s: se.Basic) -> Vec3:
    return (a[0] * s, a[1] * s, a[2] * s)


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a: Vec3, b: Vec3) -> se.Basic:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _mv(A: Mat3, v: Vec3) -> Vec3:
    """A·v"""
    return (
        A[0][0] * v[0] + A[0][1] * v[1] + A[0][2] * v[2],
        A[1][0] * v[0] + A[1][1] * v[1] + A[1][2] * v[2],
        A[2][0] * v[0] + A[2][1] * v[1] + A[2][2] * v[2],
    )


def _mtv(A: Mat3, v: Vec3) -> Vec3:
    """Aᵀ·v"""
    return (
        A[0][0] * v[0] + A[1][0] * v[1] + A[2][0] * v[2],
        A[0][1] * v[0] + A[1][1] * v[1] + A[2][1] * v[2],
        A[0][2] * v[0] + A[1][2] * v[1] + A[2][2] * v[2],
    )


def _mm(A: Mat3, B: Mat3) -> Mat3:
    return tuple(
        tuple(A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j] for j in range(3))
        for i in range(3)
    )  # type: ignore[return-value]


_ZERO_TYPE = type(ZERO)


def _zero(c: object) -> bool:
    """c == 0, structurally (SymEngine's only zero is its Zero; other numbers by value)."""
    return type(c) is _ZERO_TYPE or (type(c) in (int, float) and c == 0)


def _is_zero(v: Vec3) -> bool:
    return _zero(v[0]) and _zero(v[1]) and _zero(v[2])


def _product(rows: tuple[tuple[object, object, object], ...]) -> Callable[[Vec3], Vec3]:
    """v ↦ R·v for the rows of R, with R's structural zeros and ones skipped: the same
    expressions as :func:`_mv`, for many vectors at a fraction of the operations (an
    elementary rotation has five zeros and ones)."""
    plan = []
    for r in rows:
        terms = [(k, a) for k, a in enumerate(r) if not _zero(a)]
        plan.append(terms)

    def apply(v: Vec3) -> Vec3:
        out = []
        for terms in plan:
            if not terms:
                out.append(ZERO)
            elif len(terms) == 1:
                k, a = terms[0]
                out.append(a * v[k])
            else:
                out.append(se.Add(*[a * v[k] for k, a in terms]))
        return tuple(out)

    return apply


def _times(A: Mat3) -> Callable[[Vec3], Vec3]:
    """v ↦ A·v (:func:`_product`)."""
    return _product(A)


def _times_t(A: Mat3) -> Callable[[Vec3], Vec3]:
    """v ↦ Aᵀ·v (:func:`_product`)."""
    return _product(tuple(zip(*A, strict=True)))

def _mtm(A: Mat3, B: Mat3) -> Mat3:
    """Aᵀ·B"""
    return tuple(
        tuple(A[0][i] * B[0][j] + A[1][i] * B[1][j] + A[2][i] * B[2][j] for j in range(3))
        for i in range(3)
    )  # type: ignore[return-value]

def _vec(m: SymMatrix) -> Vec3:
    return (m.rows[0][0], m.rows[1][0], m.rows[2][0])


def _mat(m: SymMatrix) -> Mat3:
    return m.rows  # type: ignore[return-value]


def _dense(cols: dict[int, Vec3], f: int) -> SymMatrix:
    return SymMatrix(tuple(tuple(cols[j][i] if j in cols else ZERO for j in range(f))
                           for i in range(3)))
