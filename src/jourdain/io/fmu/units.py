"""SI base-unit exponents of the unit strings of model files, for FMI's ``<BaseUnit>``.

A unit string is a product and quotient of unit symbols with integer powers, read left to
right as written in model files: ``"N*s/m"``, ``"m/s^2"``, ``"kg*m^2"``, ``"1/s"``, ``"rad/s"``
(``a/b/c`` is ``a/(b·c)``). Symbols are the SI base units, a few derived and scaled ones
(``N``, ``J``, ``W``, ``Pa``, ``Hz``, ``V``, ``g``, ``mm``, ``deg``, ``rpm``, ...). A string that
does not read so gets no ``<BaseUnit>``: FMI allows a unit known by its name only.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

#: the exponents of FMI 2.0's BaseUnit, in the order of its attributes
BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def _u(factor: float = 1.0, **exps: int) -> tuple[float, tuple[int, ...]]:
    return factor, tuple(exps.get(b, 0) for b in BASE)


SYMBOLS: dict[str, tuple[float, tuple[int, ...]]] = {
    "kg": _u(kg=1), "g": _u(1e-3, kg=1), "t": _u(1e3, kg=1),
    "m": _u(m=1), "mm": _u(1e-3, m=1), "cm": _u(1e-2, m=1), "km": _u(1e3, m=1),
    "s": _u(s=1), "ms": _u(1e-3, s=1), "min": _u(60.0, s=1), "h": _u(3600.0, s=1),
    "A": _u(A=1), "K": _u(K=1), "mol": _u(mol=1), "cd": _u(cd=1),
    "rad": _u(rad=1), "deg": _u(math.pi / 180.0, rad=1), "rev": _u(2 * math.pi, rad=1),
    "rpm": _u(2 * math.pi / 60.0, rad=1, s=-1),
    "N": _u(kg=1, m=1, s=-2), "kN": _u(1e3, kg=1, m=1, s=-2),
    "J": _u(kg=1, m=2, s=-2), "W": _u(kg=1, m=2, s=-3), "kW": _u(1e3, kg=1, m=2, s=-3),
    "Pa": _u(kg=1, m=-1, s=-2), "kPa": _u(1e3, kg=1, m=-1, s=-2),
    "MPa": _u(1e6, kg=1, m=-1, s=-2), "bar": _u(1e5, kg=1, m=-1, s=-2),
    "Hz": _u(s=-1), "V": _u(kg=1, m=2, s=-3, A=-1), "C": _u(A=1, s=1),
    "Ohm": _u(kg=1, m=2, s=-3, A=-2), "1": _u(),
}

_TOKEN = re.compile(r"\s*(?:(?P<sym>[A-Za-z]+|1)\s*(?:(?:\^|\*\*)\s*(?P<exp>[+-]?\d+))?"
                    r"|(?P<op>[*/·]))")


@dataclass(frozen=True)
class BaseUnit:
    """``value_SI = factor · value`` with the SI exponents ``exponents`` (in :data:`BASE`)."""

    factor: float
    exponents: tuple[int, ...]

    def attributes(self) -> dict[str, str]:
        """The XML attributes of FMI's ``<BaseUnit>`` (zero exponents and factor 1 left out)."""
        out = {b: str(e) for b, e in zip(BASE, self.exponents, strict=True) if e}
        if self.factor != 1.0:
            out["factor"] = repr(self.factor)
        return out


def base_unit(text: str) -> BaseUnit | None:
    """The SI reading of ``text``, or None when it is not a product of known symbols."""
    pos, n = 0, len(text)
    factor, exps = 1.0, [0] * len(BASE)
    sign, expect_term = 1, True
    while pos < n:
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            return None
        pos = m.end()
        if m.group("op"):
            if expect_term:
                return None
            sign = -1 if m.group("op") == "/" else 1
            expect_term = True
            continue
        if not expect_term or m.group("sym") not in SYMBOLS:
            return None
        f, e = SYMBOLS[m.group("sym")]
        k = int(m.group("exp")) if m.group("exp") else 1
        factor *= f ** (sign * k)
        exps = [a + sign * k * b for a, b in zip(exps, e, strict=True)]
        expect_term = False
    if expect_term:
        return None
    return BaseUnit(factor, tuple(exps))


def is_si(text: str) -> bool:
    """``text`` reads as a coherent SI unit (factor 1)."""
    b = base_unit(text)
    return b is not None and b.factor == 1.0
