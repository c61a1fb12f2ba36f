"""The report's equations: the symbolic matrices of the method as MathML (section 2),
``equations.tex`` and ``equations.json``, and the nominal motions as MathML.

This is the report's SymPy work (simplification for reading, LaTeX, MathML). It depends on
the symbolic equations only, so it is computed once per model and display code and kept in
the compile cache (``<cache>/report/<key>.json``, the private one, the key a SHA-256 of the matrices' entries,
the model's names and numbers, ``max_ops`` and the source of the display code); for
``jourdain run``, when it is not in the cache, it is computed in a forked worker while the
command computes the numbers.
Simplification is bounded (:data:`REPORT_SIMPLIFY_SECONDS`); where the bound cuts it short the
entries are shown as derived, and the cache keeps what was shown.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from ...errors import JourdainError
from ...numeric.toolchain import keep_file, library_dir
from ...symbolic import to_sympy
from ...workflow import eom_matrices, has_capability
from .. import export
from ..modelfile import ModelFile
from .html import SYM, esc, headline_eom, headline_ne, headline_reactions, mathml, note

#: Matrices with more rows than this are summarized in the equations section.
MAX_DISPLAY_ROWS = 12
#: seconds for simplifying all matrices of one report for display (entries left as derived after)
REPORT_SIMPLIFY_SECONDS = 0.3
#: bump on a change of :class:`Display` (the source files below are part of the key as well)
DISPLAY_FORMAT = "jourdain-report-display/1"
_SOURCES = ("io/export.py", "symbolic.py", "io/report/equations.py", "io/report/html.py")
_LATEX_NAMES = {"M_bar": r"\bar{M}", "J_bar": r"\bar{J}", "q_c": r"\bar{q}^{c}",
                "q_e": r"\bar{q}^{e}", "M": "M", "k": "k", "q": "q"}


@dataclass
class Display:
    """The symbolic display of one model: section 2 of the page (``html``), the operation
    count of each matrix after CSE (``ops``), ``equations.tex`` without its title line
    (``tex_body``), ``equations.json`` (``json_text``) and each nominal motion as MathML
    (``nominal``, by name)."""

    html: str
    ops: dict[str, int]
    tex_body: str
    json_text: str
    nominal: dict[str, str]


def display_matrix(name: str, m: Any, system: Any, max_ops: int,
                   deadline: float | None = None) -> str:
    """``name = matrix`` in MathML (a summary by size and operation count for a large one)."""
    rows, cols = m.shape
    if rows > MAX_DISPLAY_ROWS:
        ops = export.display_ops(m)
        inner = (f"<mtext>{rows}×{cols} matrix, {ops} operations after CSE (shown in "
                 "equations.json / equations.tex)</mtext>")
    else:
        inner = export.matrix_mathml(m, system, max_ops, deadline)
    return f'<div class="eq">{mathml(f"<mrow>{SYM[name]}<mo>=</mo>{inner}</mrow>")}</div>'


def _reactions(system: Any) -> tuple[Any, str | None]:
    """The symbolic reactions stage, or why it cannot be formed."""
    if not has_capability("reactions"):
        return None, None
    try:
        return system.reactions(), None
    except JourdainError as exc:
        return None, str(exc)


def compute_display(model: ModelFile, max_ops: int) -> Display:
    """The symbolic display of ``model`` (SymPy's work, bounded in time)."""
    # one budget for simplifying every displayed matrix: the report must not wait on SymPy
    deadline = time.perf_counter() + REPORT_SIMPLIFY_SECONDS
    system = model.system
    p = len(system.bodies)
    mats = eom_matrices(system)
    ops = {k: export.display_ops(m) for k, m in mats.items()}
    s = ["<h2>2. Newton–Euler equations and equations of motion</h2>",
         "<p>Newton–Euler equations of all bodies (translational rows in the inertial frame, "
         "rotational rows in each body frame about its centre of mass):</p>",
         f'<div class="eq">{headline_ne()}</div>']
    for k in ("M_bar", "J_bar", "q_c", "q_e"):
        s.append(display_matrix(k, mats[k], system, max_ops, deadline))
    s.append("<p>Projection with J̄ᵀ eliminates the reaction forces (J̄ᵀQ̄ = 0):</p>")
    s.append(f'<div class="eq">{headline_eom()}</div>')
    for k in ("M", "k", "q"):
        s.append(display_matrix(k, mats[k], system, max_ops, deadline))
    react, error = _reactions(system)
    extra = {}
    if react is not None:
        q_count = len(react.g_names)
        s.append(f"<p>Reaction forces: Q̄ ({6 * p}×{q_count}) has one column per "
                 "constrained direction (" + ", ".join(esc(n) for n in react.g_names[:12])
                 + (", …" if q_count > 12 else "") + "); N̂·g = k̂ − q̂ gives g "
                 "without ÿ:</p>")
        s.append(f'<div class="eq">{headline_reactions()}</div>')
        s.append(display_matrix("Q_bar", react.Q_bar, system, max_ops, deadline))
        extra = {"Q_bar": react.Q_bar}
    elif error is not None:
        s.append(note(f"the reaction forces could not be formed: {error}"))
    s.append("<p class='meta'>Operation counts after common-subexpression elimination: "
             + ", ".join(f"{k} {v}" for k, v in ops.items()) + ".</p>")
    # the same compilable fragment as jourdain eom --format latex (math delimiters, the
    # column count of wide matrices); the title line is the report's own (its date)
    tex = export.latex_fragment(mats, _LATEX_NAMES, system, "", max_ops, deadline)
    eqj = {"format": "jourdain-eom/1", "model": system.name,
           "coordinates": system.coordinate_names,
           "rates": [f"{c}_d" for c in system.coordinate_names],
           "parameters": system.parameter_values, "inputs": system.input_names}
    eqj.update(export.matrices_json({**mats, **extra}, system))
    names = export.display_names(system)
    nominal = {n.name: ", ".join(
        mathml(f"<mrow>{names[c].mathml()}<mo>=</mo>"
               f"{export.expr_mathml(to_sympy(e), system)}</mrow>", block=False)
        for c, e in zip(system.coordinate_names, n.y, strict=True)) for n in model.nominal}
    return Display("".join(s), ops, tex.split("\n", 1)[1], json.dumps(eqj, indent=1), nominal)


def display_key(model: ModelFile, max_ops: int) -> str:
    """The cache key of the display of ``model``: a SHA-256 of everything it shows."""
    system = model.system
    h = hashlib.sha256()

    def add(*parts: object) -> None:
        for x in parts:
            h.update(str(x).encode("utf-8", "surrogatepass"))
            h.update(b"\x00")

    add(DISPLAY_FORMAT, max_ops, system.name, system.coordinate_names, system.input_names,
        sorted(system.parameter_values.items()))
    root = Path(__file__).resolve().parents[2]
    for rel in _SOURCES:
        h.update((root / rel).read_bytes())
    mats = dict(eom_matrices(system))
    react, error = _reactions(system)
    if react is not None:
        mats["Q_bar"] = react.Q_bar
        add(react.g_names)
    add(error)
    for k, m in mats.items():
        add(k, m.shape, *m.entries())
    for n in model.nominal:
        add(n.name, *n.y)
    return h.hexdigest()


def _cache_file(key: str) -> Path:
    """Where the display of ``key`` is kept: in the compile cache once it is known to be
    private (:func:`~jourdain.numeric.toolchain.library_dir`), as its HTML goes into pages."""
    return library_dir() / "report" / f"{key}.json"


def cached(key: str) -> Display | None:
    """The display kept under ``key``, None when there is none (or it cannot be read)."""
    try:
        return Display(**json.loads(_cache_file(key).read_text(encoding="utf-8")))
    except (OSError, ValueError, TypeError):
        return None


def keep(key: str, display: Display) -> None:
    """Keep ``display`` under ``key`` (written whole or not at all, for a concurrent reader;
    a cache that cannot be written costs time, not results)."""
    keep_file(_cache_file(key), json.dumps(asdict(display)).encode("utf-8"))


def cached_display(model: ModelFile, max_ops: int) -> Display:
    """:func:`compute_display`, from the cache when it holds the display of this model."""
    key = display_key(model, max_ops)
    display = cached(key)
    if display is None:  # not cached yet (or unreadable): computed and kept
        display = compute_display(model, max_ops)
        keep(key, display)
    return display


#: the model and options of the display a worker computes (set before it is forked)
_PENDING: tuple[ModelFile, int] | None = None


def display_in_worker(key: str) -> Display:
    """The job of a report worker: :func:`compute_display` of the model set before it was
    forked (nothing is sent), kept under ``key``."""
    assert _PENDING is not None, "the report worker was forked without a model"
    display = compute_display(*_PENDING)
    keep(key, display)
    return display


def set_pending(model: ModelFile | None, max_ops: int) -> None:
    """The model whose display a worker forked next may compute (None: no more)."""
    global _PENDING
    _PENDING = None if model is None else (model, max_ops)


def equations_section(display: Display, model: ModelFile, out: Path) -> tuple[str, list[Path]]:
    """Section 2 and its files, ``equations.tex`` (titled with the model's name and today's
    date) and ``equations.json``."""
    title = export.latex_comment(f"{model.system.name}: {_dt.date.today().isoformat()} "
                                 "(jourdain)")
    (out / "equations.tex").write_text(f"{title}\n{display.tex_body}", encoding="utf-8")
    (out / "equations.json").write_text(display.json_text, encoding="utf-8")
    return display.html, [out / "equations.tex", out / "equations.json"]
