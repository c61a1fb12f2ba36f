"""HTML pieces of the report: escaping, numbers, tables, MathML symbols and headline
equations of the method (docs/method.md), notes and the page's style sheet."""

from __future__ import annotations

import html
from collections.abc import Sequence

import numpy as np

from .. import export


def esc(s: object) -> str:
    return html.escape(str(s), quote=True)


def numstr(x: float) -> str:
    if not np.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    a = abs(x)
    return f"{x:.5g}" if 1e-3 <= a < 1e5 else f"{x:.4e}"


def html_table(rows: Sequence[Sequence[object]], header: Sequence[str] | None = None,
           cls: str = "") -> str:
    out = [f'<table class="{cls}">' if cls else "<table>"]
    if header:
        out.append("<tr>" + "".join(f"<th>{h}</th>" for h in header) + "</tr>")
    for r in rows:
        out.append("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>")
    out.append("</table>")
    return "".join(out)


def snap(a: np.ndarray, rel: float = 1e-12) -> np.ndarray:
    """Round-off (relative to the largest entry) shown as 0."""
    a = np.array(a, dtype=complex if np.iscomplexobj(a) else float)
    finite = np.isfinite(a)
    scale = float(np.abs(a[finite]).max(initial=0.0))
    if np.iscomplexobj(a):
        a.real[np.abs(a.real) <= rel * scale] = 0.0
        a.imag[np.abs(a.imag) <= rel * scale] = 0.0
    else:
        a[finite & (np.abs(a) <= rel * scale)] = 0.0
    return a


def matrix_table(a: np.ndarray, rows: Sequence[str] | None = None,
                  cols: Sequence[str] | None = None) -> str:
    a = snap(np.atleast_2d(np.asarray(a, float)))
    if a.shape[0] == 1 and rows is not None and len(rows) > 1:
        a = a.T
    body = []
    for i in range(a.shape[0]):
        label = f"<th>{esc(rows[i])}</th>" if rows is not None and i < len(rows) else ""
        body.append("<tr>" + label + "".join(f"<td>{numstr(v)}</td>" for v in a[i]) + "</tr>")
    head = ""
    if cols is not None:
        head = "<tr>" + ("<th></th>" if rows is not None else "") + "".join(
            f"<th>{esc(c)}</th>" for c in cols) + "</tr>"
    return f'<table class="matrix">{head}{"".join(body)}</table>'


def mathml(inner: str, block: bool = True) -> str:
    disp = ' display="block"' if block else ""
    return f'<math xmlns="http://www.w3.org/1998/Math/MathML"{disp}>{inner}</math>'


SYM = {
    "M_bar": export.symbol_mathml("M", bar=True), "J_bar": export.symbol_mathml("J", bar=True),
    "q_c": export.symbol_mathml("q", bar=True, sup="c"),
    "q_e": export.symbol_mathml("q", bar=True, sup="e"),
    "Q_bar": export.symbol_mathml("Q", bar=True), "M": "<mi>M</mi>", "k": "<mi>k</mi>",
    "q": "<mi>q</mi>", "g": "<mi>g</mi>", "N_hat": export.symbol_mathml("N", hat=True),
    "k_hat": export.symbol_mathml("k", hat=True), "q_hat": export.symbol_mathml("q", hat=True),
    "M_tilde": export.symbol_mathml("M", tilde=True), "P": "<mi>P</mi>", "Q": "<mi>Q</mi>",
    "h": "<mi>h</mi>", "D": "<mi>D</mi>", "G": "<mi>G</mi>", "K": "<mi>K</mi>",
    "N": "<mi>N</mi>", "B": "<mi>B</mi>",
}
DOT_Y = '<mover accent="true"><mi>y</mi><mo>˙</mo></mover>'
DDOT_Y = '<mover accent="true"><mi>y</mi><mo>¨</mo></mover>'
ETA = "<mi>η</mi>"
DETA = '<mover accent="true"><mi>η</mi><mo>˙</mo></mover>'
DDETA = '<mover accent="true"><mi>η</mi><mo>¨</mo></mover>'


def headline_ne() -> str:
    return mathml(f"<mrow>{SYM['M_bar']}<mo>⋅</mo>{SYM['J_bar']}<mo>⋅</mo>{DDOT_Y}<mo>+</mo>"
                 f"{SYM['q_c']}<mo>=</mo>{SYM['q_e']}<mo>+</mo>{SYM['Q_bar']}<mo>⋅</mo>"
                 f"<mi>g</mi></mrow>")


def headline_eom() -> str:
    return mathml(f"<mrow><mi>M</mi><mo>⋅</mo>{DDOT_Y}<mo>+</mo><mi>k</mi><mo>=</mo><mi>q</mi>"
                 f"<mo>,</mo><mspace width='1em'/><mi>M</mi><mo>=</mo><msup>{SYM['J_bar']}"
                 f"<mi>T</mi></msup>{SYM['M_bar']}{SYM['J_bar']}<mo>,</mo><mspace width='1em'/>"
                 f"<mi>k</mi><mo>=</mo><msup>{SYM['J_bar']}<mi>T</mi></msup>{SYM['q_c']}"
                 f"<mo>,</mo><mspace width='1em'/><mi>q</mi><mo>=</mo><msup>{SYM['J_bar']}"
                 f"<mi>T</mi></msup>{SYM['q_e']}</mrow>")


def headline_reactions() -> str:
    return mathml(f"<mrow>{SYM['N_hat']}<mo>⋅</mo><mi>g</mi><mo>=</mo>{SYM['k_hat']}<mo>−</mo>"
                 f"{SYM['q_hat']}<mo>,</mo><mspace width='1em'/>{SYM['N_hat']}<mo>=</mo>"
                 f"<msup>{SYM['Q_bar']}<mi>T</mi></msup><msup>{SYM['M_bar']}<mrow><mo>−</mo>"
                 f"<mn>1</mn></mrow></msup>{SYM['Q_bar']}</mrow>")


def headline_lin() -> str:
    return mathml(f"<mrow>{SYM['M_tilde']}<mo>⋅</mo>{DDETA}<mo>+</mo><mo>(</mo><mi>D</mi>"
                 f"<mo>+</mo><mi>G</mi><mo>)</mo><mo>⋅</mo>{DETA}<mo>+</mo><mo>(</mo><mi>K</mi>"
                 f"<mo>+</mo><mi>N</mi><mo>)</mo><mo>⋅</mo>{ETA}<mo>=</mo><mi>h</mi></mrow>")



CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1100px;
margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{font-size:1.7em;margin-bottom:.2em}h2{border-bottom:1px solid #ddd;padding-bottom:.2em;
margin-top:2em}h3{margin-top:1.4em}
table{border-collapse:collapse;margin:.5em 0;font-size:.9em}
td,th{border:1px solid #ddd;padding:.25em .6em;text-align:right}
th{background:#f4f4f4}table.info td,table.info th{text-align:left}
table.matrix td{font-family:ui-monospace,Consolas,monospace}
.note{background:#fff7e0;border-left:4px solid #e0a800;padding:.4em .8em;margin:.6em 0}
.ok{color:#11772d;font-weight:600}.bad{color:#b00020;font-weight:600}
.eq{overflow-x:auto;margin:.5em 0 1em 0;padding:.3em 0}
math{font-size:1.1em;font-family:"STIX Two Math","Latin Modern Math","Cambria Math",
"DejaVu Math TeX Gyre",math}.meta{color:#666;font-size:.9em}
svg{max-width:100%;height:auto}
"""


def note(text: str) -> str:
    return f'<p class="note">{esc(text)}</p>'

