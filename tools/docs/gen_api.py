"""The API reference (mkdocs-gen-files script, run by ``mkdocs build``).

The page list is not written down anywhere: it is found by walking src/jourdain, one page per
public module or package (no part of its dotted name starts with ``_``), so a module that is
added, moved or split shows up on the next build without a change here. The pages themselves
are rendered by mkdocstrings from the docstrings (static analysis with Griffe; the package is
imported only to read ``jourdain.__all__`` and where each of its names is defined).

* ``reference/index.md``: the public API, ``jourdain.__all__``, one row per name linking to
  the page that documents it (an unresolvable link fails the strict build, so every name must
  be documented where it is defined); a value (a symbol, a constant) names the module whose
  source assigns it;
* ``reference/<package>/index.md`` and ``reference/<package>/<module>.md``: one page each, a
  package's page showing what its ``__init__`` defines itself (its re-exports are documented on
  the page of the module that defines them);
* ``reference/SUMMARY.md``: the navigation (mkdocs-literate-nav).

mkdocs-gen-files runs this file with ``runpy.run_path`` (``__name__ == "<run_path>"``); imported
(tests/test_docs_site.py) it only defines its functions.
"""

from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"
PACKAGE = "jourdain"


def public_modules() -> list[tuple[str, bool]]:
    """(dotted name, is a package) of every public module of the package, sorted by name."""
    found = []
    for path in sorted((SRC / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        if parts[-1] == "__main__" or any(p.startswith("_") for p in parts):
            continue
        # a module of a folder without __init__.py is no module of the package
        if not all((SRC / Path(*parts[:i]) / "__init__.py").is_file()
                   for i in range(1, len(parts))):
            continue
        found.append((".".join(parts), is_package))
    return sorted(found)


def own_members(module: Any) -> list[str]:
    """The public classes and functions a module defines itself (not those it imports)."""
    names = []
    for name, obj in vars(module).items():
        if name.startswith("_") or not (inspect.isclass(obj) or inspect.isfunction(obj)):
            continue
        if getattr(obj, "__module__", None) == module.__name__:
            names.append(name)
    return names


def page_of(module: str, is_package: bool) -> str:
    parts = module.split(".")
    return "/".join(["reference", *parts, "index.md"] if is_package
                    else ["reference", *parts[:-1], parts[-1] + ".md"])


def defining_module(name: str, modules: list[tuple[str, bool]]) -> str | None:
    """The public module whose source assigns ``name`` at its top level, if any."""
    assign = re.compile(rf"^{re.escape(name)}\s*(?::[^=]*)?=", re.M)
    for module, is_package in modules:
        path = SRC / Path(*module.split("."))
        source = path / "__init__.py" if is_package else path.with_suffix(".py")
        if assign.search(source.read_text(encoding="utf-8")):
            return module
    return None


def api_row(name: str, obj: Any, modules: list[tuple[str, bool]]) -> str:
    module = getattr(obj, "__module__", None)
    if (inspect.isclass(obj) or inspect.isfunction(obj)) and module and \
            module.split(".")[0] == PACKAGE:
        path = f"{module}.{obj.__qualname__}"
        kind = "class" if inspect.isclass(obj) else "function"
        return f"| [`{name}`][{path}] | {kind} | `{module}` |"
    if type(obj).__module__.split(".")[0] == "symengine":
        kind = "function (SymEngine)" if callable(obj) else "constant (SymEngine)"
        return f"| `{name}` | {kind}, for expressions | |"
    where = defining_module(name, modules)
    return f"| `{name}` | {type(obj).__name__} | {f'`{where}`' if where else ''} |"


def main() -> None:
    import mkdocs_gen_files  # the documentation build's own dependency

    modules = public_modules()
    nav = mkdocs_gen_files.Nav()
    nav["jourdain (public API)"] = "index.md"

    top = importlib.import_module(PACKAGE)
    lines = [
        "# API reference",
        "",
        "`import jourdain as jd` gives the names below (`jourdain.__all__`), each documented on",
        "the page of the module that defines it. The modules, stage by stage as",
        "[the method](../method.md) runs, are in the navigation; their pages are generated from",
        "the docstrings at every build.",
        "",
        "| name | kind | defined in |",
        "| --- | --- | --- |",
    ]
    lines += [api_row(name, getattr(top, name), modules) for name in top.__all__]
    with mkdocs_gen_files.open("reference/index.md", "w") as f:
        f.write("\n".join(lines) + "\n")

    for module, is_package in modules:
        page = page_of(module, is_package)
        if is_package:
            members = own_members(importlib.import_module(module))
            options = ("    options:\n      members: " + (str(members) if members else "false")
                       + "\n      show_submodules: false\n")
        else:
            options = ""
        with mkdocs_gen_files.open(page, "w") as f:
            f.write(f"# `{module}`\n\n::: {module}\n" + options)
        key = tuple(module.split("."))
        nav[key if len(key) > 1 else (module,)] = page[len("reference/"):]

    with mkdocs_gen_files.open("reference/SUMMARY.md", "w") as f:
        f.writelines(nav.build_literate_nav())


if __name__ in ("__main__", "<run_path>"):
    main()
