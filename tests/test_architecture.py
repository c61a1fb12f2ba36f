"""The package's architecture (issue 16), checked from the source: the import graph read from
the AST of every module of src/jourdain, with no module imported.

- No import circle between modules (a package's ``__init__`` importing its own submodules is
  the one allowed loop, since importing a submodule runs its package's ``__init__`` first).
- The model (``jourdain.model``) imports nothing above it: only :data:`MODEL_MAY_IMPORT`.
- Floors (:data:`FLOORS`, the same table as in docs/architecture.md): an import never points to
  a higher floor.
- Every submodule is reachable as a module: ``import_module("jourdain.a.b")`` is
  ``jourdain.a.b`` (no package re-exports a function under the name of its submodule).
- No module over :data:`MAX_LINES` lines unless its first docstring has a line starting with
  ``Length:`` that gives the reason.

Imports counted: top-level and inside functions, ``import a.b`` and ``from a import b``,
absolute and relative, ``if TYPE_CHECKING:`` blocks included (a type-only import up the floors is
still a dependency of the source on a higher layer). ``from pkg import name`` counts as importing
the submodule ``pkg.name`` where that is a module, else ``pkg`` (its ``__init__``).
"""

from __future__ import annotations

import ast
import importlib
import pkgutil
import re
import warnings
from functools import cache
from pathlib import Path

import pytest

import jourdain

ROOT = Path(jourdain.__file__).parent
MAX_LINES = 400

# What the model layer may import from the package: itself, the errors (jourdain.errors) and
# the expression language that reads its strings (jourdain.io.expressions, which imports only
# the errors; Body(mass="m") is read as a model file's mass is).
MODEL_MAY_IMPORT = ("jourdain.model", "jourdain.errors", "jourdain.io.expressions")

# The floors, lowest first (docs/architecture.md has the same table). A module belongs to the
# floor of the longest prefix listed; a module may import from its own floor or any floor below.
FLOORS: tuple[tuple[str, ...], ...] = (
    # 0 foundations: the errors, the symbolic matrix, the expression graph (CSE,
    #   differentiation) and identity maps
    ("jourdain.errors", "jourdain.version", "jourdain.identity", "jourdain.symbolic", "jourdain.graph",
     "jourdain.extras"),
    # 1 the model: the description a user writes (pure, immutable data), its units, and the
    #   expression language that reads its strings (model files and the Python API alike;
    #   it imports only jourdain.errors, though its package sits in jourdain.io)
    ("jourdain.model", "jourdain.units", "jourdain.io.expressions"),
    # 2 the stages of the method: kinematics → Newton–Euler → projection → reactions →
    #   linearization, and what they share (kinematic measures)
    ("jourdain.measures", "jourdain.stages"),
    # 3 numbers: generated and compiled code, evaluation; the elastic bodies' finite elements
    #   and modal data (NumPy/SciPy only)
    ("jourdain.numeric", "jourdain.elastic"),
    # 4 simulation and analysis of the equations, and the numbers of closed systems (the
    #   constraint stage's partition, assembly, M, k, q, reactions and motion on the manifold)
    ("jourdain.simulation", "jourdain.analysis", "jourdain.equilibrium", "jourdain.wrenches",
     "jourdain.loops"),
    # 5 the pipeline: jourdain.System with the stages as cached methods
    ("jourdain.pipeline",),
    # 6 builders of systems and what works on whole models: example models, studies, model
    #   files, URDF, export, viewer, FMU
    ("jourdain.models", "jourdain.study", "jourdain.io"),
    # 7 the workflow shared by the report and the command line
    ("jourdain.workflow",),
    # 8 the report and the command line
    ("jourdain.io.report", "jourdain.cli", "jourdain.study.cli"),
    # 9 the public API
    ("jourdain",),
)

# Known offenders while issue 16 is being worked on (parallel sessions own these files): each
# entry is removed when its module is fixed. ("lines", module): longer than MAX_LINES without a
# "Length:" reason; ("floor", importer, imported): an import up the floors; ("cycle", module):
# a module on an import circle; ("shadow", module): a submodule its package's attribute hides.
PENDING: set[tuple[str, ...]] = set()  # empty: every offender fixed (the linearization last, H9)


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@cache
def modules() -> dict[str, Path]:
    """Every module of the package by dotted name."""
    return {_module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def _is_package(name: str) -> bool:
    return modules()[name].name == "__init__.py"


def _resolve(importer: str, level: int, module: str | None) -> str:
    if level == 0:
        return module or ""
    base = importer.split(".")
    if not _is_package(importer):
        base = base[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join([*base, module] if module else base)


def _target(name: str) -> str | None:
    """The module of the package that importing ``name`` runs (its longest known prefix)."""
    parts = name.split(".")
    while parts:
        cand = ".".join(parts)
        if cand in modules():
            return cand
        parts.pop()
    return None


def imports_in(name: str, source: str) -> frozenset[str]:
    """The package's modules that ``source``, the text of module ``name``, imports (anywhere)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "jourdain":
                    out.add(a.name)
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(name, node.level, node.module)
            if base.split(".")[0] != "jourdain":
                continue
            for a in node.names:
                sub = f"{base}.{a.name}"
                out.add(sub if sub in modules() else base)
    targets = {_target(n) for n in out}
    return frozenset(t for t in targets if t is not None and t != name)


@cache
def imports_of(name: str) -> frozenset[str]:
    """The package's modules that module ``name`` imports."""
    return imports_in(name, modules()[name].read_text(encoding="utf-8"))


def graph() -> dict[str, frozenset[str]]:
    return {m: imports_of(m) for m in modules()}


def _own_init(importer: str, imported: str) -> bool:
    """A package's __init__ importing one of its own submodules (the allowed loop)."""
    return _is_package(importer) and imported.startswith(importer + ".")


def cycles() -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan), edges from a package's
    __init__ to its own submodules left out."""
    g = {m: sorted(t for t in ts if not _own_init(m, t)) for m, ts in graph().items()}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return out


def floor(name: str) -> int:
    best, level = -1, -1
    for k, prefixes in enumerate(FLOORS):
        for p in prefixes:
            under = name.startswith(p + ".") and p != "jourdain"  # "jourdain": the __init__ only
            if (name == p or under) and len(p) > best:
                best, level = len(p), k
    assert level >= 0, f"{name} is on no floor: add it to FLOORS (and docs/architecture.md)"
    return level


def test_graph_is_read() -> None:
    """The reader finds the imports it is meant to (a check of the checker): relative and
    absolute, ``from pkg import submodule``, and function-level ones."""
    source = """
from __future__ import annotations
import numpy
from ..model import System
from ..model.joints import Rot
from . import kinematics
import jourdain.numeric.diagnose
from jourdain import errors, __version__
if TYPE_CHECKING:
    from ..simulation.results import Results
def f():
    from ..numeric import lambdify
"""
    assert imports_in("jourdain.stages.projection", source) == {
        "jourdain.model", "jourdain.model.joints", "jourdain.stages.kinematics",
        "jourdain.numeric.diagnose", "jourdain.errors", "jourdain", "jourdain.simulation.results",
        "jourdain.numeric"}
    # in a package's __init__, "." is the package itself
    assert imports_in("jourdain.model", "from .bodies import Body") == {"jourdain.model.bodies"}
    assert _resolve("jourdain.stages.projection", 2, "model.system") == "jourdain.model.system"
    g = graph()
    assert "jourdain.errors" in g["jourdain.model.system"]
    assert "jourdain.pipeline" in g["jourdain"]


def test_no_import_circles() -> None:
    found = [c for c in cycles() if not all(("cycle", m) in PENDING for m in c)]
    assert not found, f"import circles: {found}"


def test_model_imports_nothing_above_it() -> None:
    bad = sorted(
        (m, t) for m, ts in graph().items() if m == "jourdain.model" or m.startswith("jourdain.model.")
        for t in ts if not any(t == p or t.startswith(p + ".") for p in MODEL_MAY_IMPORT)
    )
    assert not bad, f"the model imports from above it: {bad}"


def test_floors_point_down() -> None:
    bad = sorted(
        (m, t) for m, ts in graph().items() for t in ts
        if floor(t) > floor(m) and not _own_init(m, t) and ("floor", m, t) not in PENDING
    )
    assert not bad, "imports up the floors (importer, imported): " + ", ".join(
        f"{m} (floor {floor(m)}) → {t} (floor {floor(t)})" for m, t in bad)


def test_submodules_are_reachable_as_modules() -> None:
    bad = []
    for info in pkgutil.walk_packages(jourdain.__path__, "jourdain."):
        if info.name.endswith(".__main__"):  # running it is the command line
            continue
        mod = importlib.import_module(info.name)
        parent_name, _, leaf = info.name.rpartition(".")
        parent = importlib.import_module(parent_name)
        if getattr(parent, leaf, None) is not mod and ("shadow", info.name) not in PENDING:
            bad.append(f"{parent_name}.{leaf} is {type(getattr(parent, leaf, None)).__name__}")
    assert not bad, f"re-exports shadow submodules: {bad}"


def _length_reason(path: Path) -> bool:
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
    return any(line.strip().startswith("Length:") for line in doc.splitlines())


def test_module_length() -> None:
    long = sorted(
        f"{m} ({n} lines)" for m, p in modules().items()
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES
        and not _length_reason(p) and ("lines", m) not in PENDING
    )
    assert not long, f"modules over {MAX_LINES} lines without a 'Length:' reason: {long}"


def test_pending_entries_are_still_needed() -> None:
    """An entry of PENDING whose module is fixed is to be removed (the set only shrinks): a
    warning, not a failure, since the owners of the modules fix them while this file lists
    them."""
    g = graph()
    on_cycle = {m for c in cycles() for m in c}
    stale = []
    for entry in sorted(PENDING):
        kind, m, *rest = entry
        if m not in modules():
            stale.append(entry)
        elif kind == "lines":
            p = modules()[m]
            if len(p.read_text(encoding="utf-8").splitlines()) <= MAX_LINES or _length_reason(p):
                stale.append(entry)
        elif kind == "floor":
            if rest[0] not in g[m] or floor(rest[0]) <= floor(m):
                stale.append(entry)
        elif kind == "cycle" and m not in on_cycle:
            stale.append(entry)
        elif kind == "shadow":
            parent, _, leaf = m.rpartition(".")
            if getattr(importlib.import_module(parent), leaf, None) is importlib.import_module(m):
                stale.append(entry)
    if stale:
        warnings.warn(f"PENDING entries no longer needed (remove them): {stale}", stacklevel=1)


@pytest.mark.parametrize("name", ["jourdain.stages.projection", "jourdain.analysis.modes",
                                  "jourdain.simulation.simulate"])
def test_known_names_are_modules(name: str) -> None:
    """The names that used to be shadowed by functions of the same name."""
    import types

    assert isinstance(importlib.import_module(name), types.ModuleType)
    parent, _, leaf = name.rpartition(".")
    assert isinstance(getattr(importlib.import_module(parent), leaf), types.ModuleType)


def test_public_api_is_listed_once_and_documented() -> None:
    """``jourdain.__all__``: no name twice, every name there, classes and functions with their
    own docstring (not a dataclass's generated signature), the values named in the package's
    docstring; each subpackage's ``__all__`` names attributes that exist and no submodule."""
    names = jourdain.__all__
    assert len(names) == len(set(names)), "a name listed twice in jourdain.__all__"
    package_doc = jourdain.__doc__ or ""
    undocumented = []
    for name in names:
        obj = getattr(jourdain, name)
        ours = str(getattr(obj, "__module__", "")).startswith("jourdain")
        if ours and (isinstance(obj, type) or callable(obj)):
            doc = (obj.__doc__ or "").strip()
            if not doc or doc.startswith(f"{name}("):
                undocumented.append(name)
        elif f"``{name}``" not in package_doc:
            undocumented.append(name)
    assert not undocumented, f"public names without documentation: {undocumented}"
    # classes and functions defined in the package and used from the top level are listed
    public = {n for n, o in vars(jourdain).items() if not n.startswith("_")
              and not isinstance(o, type(jourdain)) and str(getattr(o, "__module__", ""))
              .startswith("jourdain.")}
    assert public <= set(names), f"not in jourdain.__all__: {sorted(public - set(names))}"
    for info in pkgutil.walk_packages(jourdain.__path__, "jourdain."):
        if not info.ispkg:
            continue
        pkg = importlib.import_module(info.name)
        for name in getattr(pkg, "__all__", ()):
            assert hasattr(pkg, name), f"{info.name}.__all__ lists {name}, which it lacks"
            sub = f"{info.name}.{name}"
            assert sub not in modules() or isinstance(getattr(pkg, name), type(jourdain)) \
                or ("shadow", sub) in PENDING, f"{info.name}.__all__ shadows a submodule"


def test_floor_table_in_the_documentation_matches() -> None:
    """docs/architecture.md shows the floors of :data:`FLOORS`, row by row, and has a line in
    its tree for every folder of the package."""
    doc = (ROOT.parents[1] / "docs" / "architecture.md").read_text(encoding="utf-8")
    rows = [line for line in doc.splitlines() if line.startswith("| ") and line[2].isdigit()]
    table = tuple(tuple(re.findall(r"`(jourdain[\w.]*)`", row.split("|")[2])) for row in rows)
    assert table == FLOORS
    tree = doc[doc.index("## The tree"):]
    folders = sorted({p.parent.relative_to(ROOT).as_posix() for p in modules().values()} - {"."})
    missing = [f for f in folders if not re.search(rf"{re.escape(f.split('/')[-1])}/\s", tree)]
    assert not missing, f"folders without a line in the tree of docs/architecture.md: {missing}"
