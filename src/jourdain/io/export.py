"""Exports of symbolic matrices: plain text, LaTeX, MathML (presentation) and JSON.

Names are shown as an engineer writes them: ``phi1`` → φ₁, its rate ``phi1_d`` → φ̇₁,
``Omega`` → Ω, ``m2`` → m₂. Matrices larger than a cap (operation count after common-subexpression
elimination) are summarized by their size and operation count instead of being printed, because a
page of expressions helps nobody. SymPy is used for display only; the heavy work stays in
SymEngine.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..graph import cse as graph_cse
from ..symbolic import (  # noqa: F401 - the display settings, re-exported
    MAX_DISPLAY_OPS,
    SIMPLIFY_OPS,
    SIMPLIFY_SECONDS,
    SymMatrix,
    simplified_sympy,
    to_sympy,
)

if TYPE_CHECKING:
    from ..model.system import System

#: Matrices with more rows are summarized in text output (a 36×36 M̄ helps nobody on a terminal).
MAX_TEXT_ROWS = 18

_GREEK = {
    "alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "epsilon": "ε", "zeta": "ζ",
    "eta": "η", "theta": "θ", "iota": "ι", "kappa": "κ", "lambda": "λ", "lam": "λ", "mu": "μ",
    "nu": "ν", "xi": "ξ", "rho": "ρ", "sigma": "σ", "tau": "τ", "upsilon": "υ", "phi": "φ",
    "chi": "χ", "psi": "ψ", "omega": "ω",
    "Gamma": "Γ", "Delta": "Δ", "Theta": "Θ", "Lambda": "Λ", "Xi": "Ξ", "Sigma": "Σ",
    "Phi": "Φ", "Psi": "Ψ", "Omega": "Ω",
}
_LATEX_GREEK = {k: ("\\varphi" if k == "phi" else "\\lambda" if k == "lam" else "\\" + k)
                for k in _GREEK}
_NAME = re.compile(r"^([A-Za-z]+?)(\d*)(?:_([A-Za-z0-9]+))?$")


@dataclass(frozen=True)
class DisplayName:
    """How one symbol is shown: ``base`` (letters or a Greek letter), subscript, dots."""

    base: str
    latex_base: str
    sub: str
    dots: int

    def latex(self) -> str:
        b = self.latex_base if len(self.base) == 1 else f"\\mathrm{{{self.latex_base}}}"
        if self.dots == 1:
            b = f"\\dot{{{b}}}"
        elif self.dots == 2:
            b = f"\\ddot{{{b}}}"
        return f"{b}_{{{self.sub}}}" if self.sub else b

    def mathml(self) -> str:
        variant = "" if len(self.base) == 1 else ' mathvariant="normal"'
        b = f"<mi{variant}>{_esc(self.base)}</mi>"
        if self.dots:
            dot = "˙" if self.dots == 1 else "¨"
            b = f'<mover accent="true">{b}<mo>{dot}</mo></mover>'
        if self.sub:
            sub = f"<mn>{self.sub}</mn>" if self.sub.isdigit() else f"<mi>{_esc(self.sub)}</mi>"
            b = f"<msub>{b}{sub}</msub>"
        return b

    def text(self) -> str:
        dots = {0: "", 1: "\u0307", 2: "\u0308"}[self.dots]
        return f"{self.base}{dots}" + (f"_{self.sub}" if self.sub else "")


def display_name(name: str, dots: int = 0) -> DisplayName:
    """Split ``phi1``, ``m_r``, ``Omega`` into a Greek or Latin base and a subscript."""
    m = _NAME.match(name)
    if not m:
        return DisplayName(name, name.replace("_", "\\_"), "", dots)
    base, digits, suffix = m.group(1), m.group(2), m.group(3) or ""
    sub = ",".join(x for x in (digits, suffix) if x)
    if base in _GREEK:
        return DisplayName(_GREEK[base], _LATEX_GREEK[base], sub, dots)
    return DisplayName(base, base, sub, dots)


def display_names(system: System) -> dict[str, DisplayName]:
    """Display names of every symbol of ``system``: coordinates with their rates and
    accelerations (dots), parameters, inputs."""
    out: dict[str, DisplayName] = {}
    for c in system.coordinate_names:
        out[c] = display_name(c)
        out[f"{c}_d"] = display_name(c, 1)
        out[f"{c}_dd"] = display_name(c, 2)
    for n in [*dict(system.parameters), *system.input_names]:
        out[n] = display_name(n)
    return out


def _esc(s: str) -> str:
    return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


# ------------------------------------------------------------------------------------------
# sizes and simplification for display
# ------------------------------------------------------------------------------------------

def display_ops(m: SymMatrix) -> int:
    """Operation count of a matrix after graph CSE (what a reader would have to read)."""
    return m.count_ops(cse=True)


def too_large(m: SymMatrix, max_ops: int = MAX_DISPLAY_OPS) -> bool:
    return display_ops(m) > max_ops


def to_sympy_matrix(m: SymMatrix, simplify: bool = True, deadline: float | None = None) -> Any:
    """The matrix as SymPy simplified for reading (:func:`jourdain.symbolic.simplified_sympy`:
    cancellations, real symbols so that ``sqrt((x + 1)**2)`` reads ``|x + 1|``, trigonometric
    identities for small entries), within ``deadline`` (a ``time.perf_counter()`` value;
    default :data:`SIMPLIFY_SECONDS` from now); memoized per matrix."""
    return simplified_sympy(m, simplify, deadline)


# ------------------------------------------------------------------------------------------
# LaTeX
# ------------------------------------------------------------------------------------------

#: Line breaks (which end a TeX comment), the other control characters and the Unicode line
#: separators (which editors show as line breaks).
_TEX_LINE_BREAKS = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]+")


def latex_comment(text: str) -> str:
    """``text`` (a model's name, a title) as one TeX comment line ``% text``: line breaks and
    other control characters become spaces, so nothing of ``text`` can leave the comment and be
    read by TeX as commands (``\\immediate\\write18{...}`` after a newline in a name)."""
    return "% " + _TEX_LINE_BREAKS.sub(" ", text)


def latex_symbol_names(system: System) -> dict[Any, str]:
    import sympy

    return {sympy.Symbol(n): d.latex() for n, d in display_names(system).items()}


def matrix_latex(m: SymMatrix, system: System, max_ops: int = MAX_DISPLAY_OPS,
                 deadline: float | None = None) -> str:
    """LaTeX of ``m`` (a ``pmatrix``), or a summary ``\\text{6×2 matrix, 153 operations}``."""
    import sympy

    if too_large(m, max_ops):
        n, k = m.shape
        return f"\\text{{{n}$\\times${k} matrix, {display_ops(m)} operations after CSE}}"
    return sympy.latex(to_sympy_matrix(m, deadline=deadline), symbol_names=latex_symbol_names(system),
                       mat_str="pmatrix", mat_delim="")


def latex_fragment(matrices: Mapping[str, SymMatrix], symbols: Mapping[str, str],
                   system: System, title: str, max_ops: int = MAX_DISPLAY_OPS,
                   deadline: float | None = None) -> str:
    """A LaTeX fragment to ``\\input`` into a document that loads ``amsmath``: a comment line
    with ``title``, ``\\setcounter{MaxMatrixCols}{n}`` for the widest matrix printed (amsmath
    allows 10 columns by default; M̄ of two bodies has 12), and one displayed equation
    ``\\[ symbol = matrix \\]`` per matrix (a summary for matrices above ``max_ops``).
    ``symbols`` gives the LaTeX of each matrix's name."""
    cols = 10
    body = []
    for name, m in matrices.items():
        tex = matrix_latex(m, system, max_ops, deadline)
        if "\\begin{pmatrix}" in tex:
            cols = max(cols, m.shape[1])
        body += [f"\\[ {symbols.get(name, name)} = {tex} \\]", ""]
    head = [latex_comment(f"{title} (jourdain)"),
            "% A LaTeX fragment: \\input it into a document that loads amsmath.",
            f"\\setcounter{{MaxMatrixCols}}{{{cols}}}", ""]
    return "\n".join([*head, *body]).rstrip() + "\n"


# ------------------------------------------------------------------------------------------
# MathML
# ------------------------------------------------------------------------------------------

def _printer(system: System) -> Any:
    from sympy.printing.mathml import MathMLPresentationPrinter

    names = display_names(system)

    class Printer(MathMLPresentationPrinter):
        """SymPy's presentation printer with jourdain's names (dots for rates)."""

        def _print_Symbol(self, sym: Any, style: str = "plain") -> Any:  # noqa: N802
            d = names.get(sym.name)
            if d is None:
                return super()._print_Symbol(sym, style)
            return _element(self.dom, d)

    return Printer({"mat_delim": "(", "mul_symbol": None})


def _element(dom: Any, d: DisplayName) -> Any:
    """A minidom element for a display name."""
    base = dom.createElement("mi")
    base.appendChild(dom.createTextNode(d.base))
    if len(d.base) > 1:
        base.setAttribute("mathvariant", "normal")
    if d.dots:
        over = dom.createElement("mover")
        over.setAttribute("accent", "true")
        mo = dom.createElement("mo")
        mo.appendChild(dom.createTextNode("˙" if d.dots == 1 else "¨"))
        over.appendChild(base)
        over.appendChild(mo)
        base = over
    if d.sub:
        msub = dom.createElement("msub")
        msub.appendChild(base)
        sub = dom.createElement("mn" if d.sub.isdigit() else "mi")
        sub.appendChild(dom.createTextNode(d.sub))
        msub.appendChild(sub)
        base = msub
    return base


def expr_mathml(expr: Any, system: System) -> str:
    """Presentation MathML (without the ``<math>`` element) of a SymPy expression or matrix."""
    return _printer(system).doprint(expr)


def matrix_mathml(m: SymMatrix, system: System, max_ops: int = MAX_DISPLAY_OPS,
                  deadline: float | None = None) -> str:
    """Presentation MathML of ``m`` (inner content), or a summary text for large matrices."""
    if too_large(m, max_ops):
        n, k = m.shape
        return (f"<mtext>{n}×{k} matrix, {display_ops(m)} operations after CSE (too large to "
                "print)</mtext>")
    return expr_mathml(to_sympy_matrix(m, deadline=deadline), system)


def symbol_mathml(text: str, bar: bool = False, hat: bool = False, tilde: bool = False,
                  sup: str = "", args: str = "") -> str:
    """A matrix symbol such as M̄ or q̄^c as MathML."""
    b = f"<mi>{_esc(text)}</mi>"
    for flag, mark in ((bar, "¯"), (hat, "^"), (tilde, "~")):
        if flag:
            b = f'<mover accent="true">{b}<mo>{mark}</mo></mover>'
    if sup:
        b = f"<msup>{b}<mi>{_esc(sup)}</mi></msup>"
    return b + args


# ------------------------------------------------------------------------------------------
# text and JSON
# ------------------------------------------------------------------------------------------

def matrix_text(m: SymMatrix, system: System, max_ops: int = MAX_DISPLAY_OPS) -> str:
    """Unicode pretty print of ``m`` (SymPy), or a summary for large matrices."""
    import sympy

    n, k = m.shape
    if too_large(m, max_ops) or n > MAX_TEXT_ROWS:
        return f"<{n}×{k} matrix, {display_ops(m)} operations after CSE; use --format json>"
    return sympy.pretty(to_sympy_matrix(m).subs(_text_symbols(system)), use_unicode=True,
                        wrap_line=False)


def _text_symbols(system: System) -> dict[Any, Any]:
    import sympy

    out = {}
    for n, d in display_names(system).items():
        label = d.base + {0: "", 1: "\u0307", 2: "\u0308"}[d.dots]
        out[sympy.Symbol(n)] = sympy.Symbol(f"{label}_{d.sub}" if d.sub else label)
    return out


def matrices_json(matrices: Mapping[str, SymMatrix], system: System) -> dict[str, Any]:
    """The matrices as JSON-ready data with shared subexpressions as temporaries.

    ``{"temporaries": [[name, expr], ...], "matrices": {name: {"shape": [n, m],
    "entries": [[expr, ...], ...]}}}``; expressions are strings in jourdain's expression syntax
    (``**`` for powers), in terms of the coordinates, rates ``<name>_d``, parameters, inputs,
    ``t`` and the temporaries, which are listed in dependency order.
    """
    names = list(matrices)
    flat: list[se.Basic] = []
    for n in names:
        flat.extend(matrices[n].entries())
    reserved = set(display_names(system))
    prefix = "tmp"
    while any(r.startswith(prefix) for r in reserved):
        prefix = "_" + prefix
    c = graph_cse(flat, prefix=prefix)
    out: dict[str, Any] = {"temporaries": [[str(s), _expr_str(e)] for s, e in c.temporaries],
                           "matrices": {}}
    i = 0
    for n in names:
        rows, cols = matrices[n].shape
        entries = [[_expr_str(c.outputs[i + r * cols + k]) for k in range(cols)]
                   for r in range(rows)]
        i += rows * cols
        out["matrices"][n] = {"shape": [rows, cols], "entries": entries}
    return out


def _expr_str(e: se.Basic) -> str:
    # SymEngine prints abs as Abs; the expression language says abs
    return re.sub(r"\bAbs\(", "abs(", str(e))


#: In text output, numbers below this fraction of the largest entry of their matrix or vector
#: (or of a given scale) are shown as 0: round-off of evaluations and linear solves (a few eps
#: times the condition number), far below the 6 significant digits shown. JSON output keeps
#: the numbers as computed.
ROUNDOFF_RTOL = 1e-10


def chop(values: Any, scale: Any = None, rtol: float = ROUNDOFF_RTOL) -> Any:
    """``values`` (an array) with entries ``|x| ≤ rtol·max|scale|`` set to 0 (``scale``
    defaults to ``values``; NaN and inf are kept); ``-0.0`` becomes ``0.0``."""
    a = np.array(values, dtype=float)
    ref = np.abs(np.asarray(a if scale is None else scale, dtype=float))
    ref = ref[np.isfinite(ref)]
    tol = rtol * float(ref.max(initial=0.0))
    with np.errstate(invalid="ignore"):
        a[np.abs(a) <= tol] = 0.0
    return a + 0.0


def format_array(values: Any, scale: Any = None) -> str:
    """A matrix or vector for text output: round-off shown as 0 (:func:`chop`), 6 significant
    digits."""
    return np.array2string(chop(values, scale), precision=6, suppress_small=True,
                           max_line_width=120, threshold=10_000)


def nested(values: Iterable[Any]) -> Sequence[Any]:
    """NumPy arrays (or nested sequences) to lists of floats for JSON."""
    return np.asarray(values, dtype=float).tolist()
