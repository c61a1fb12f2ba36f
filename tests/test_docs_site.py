"""The documentation site's sources (mkdocs.yml, docs/, tools/docs/): the real check is
``make docs`` (mkdocs build --strict, tutorials executed, examples run); these tests catch the
mistakes that need no build, without the docs extra installed: a page left out of the
navigation or named there but missing, a tutorial that is no valid Jupytext script, a module
the API reference would miss, an example without its gallery text, and the offline rule."""

from __future__ import annotations

import ast
import importlib.util
import logging
import pkgutil
import re
from pathlib import Path
from types import ModuleType, SimpleNamespace
from typing import Any

import pytest

import jourdain

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
# pages the build generates (tools/docs/gen_*.py) rather than docs/ holding them
GENERATED = {"contributing.md", "changelog.md", "gallery/", "reference/"}


def _load(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"_docs_{name}", ROOT / "tools/docs" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _nav_entries(node: Any) -> list[str]:
    if isinstance(node, str):
        return [node]
    if isinstance(node, list):
        return [e for item in node for e in _nav_entries(item)]
    if isinstance(node, dict):
        return [e for value in node.values() for e in _nav_entries(value)]
    raise TypeError(f"mkdocs.yml nav: unexpected entry {node!r}")


def _config() -> dict[str, Any]:
    yaml = pytest.importorskip("yaml")
    return yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))


def test_nav_lists_every_page_and_only_pages_that_exist() -> None:
    entries = _nav_entries(_config()["nav"])
    assert len(entries) == len(set(entries)), "a page is listed twice in mkdocs.yml's nav"
    pages = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.md")}
    pages |= {p.relative_to(DOCS).as_posix() for p in (DOCS / "tutorials").glob("*.py")}
    missing = sorted(e for e in entries if e not in pages and e not in GENERATED)
    assert not missing, f"mkdocs.yml's nav names pages that docs/ does not have: {missing}"
    left_out = sorted(pages - set(entries))
    assert not left_out, f"pages of docs/ missing from mkdocs.yml's nav: {left_out}"


def test_tutorials_are_jupytext_percent_scripts() -> None:
    tutorials = sorted((DOCS / "tutorials").glob("*.py"))
    assert len(tutorials) >= 3
    for path in tutorials:
        text = path.read_text(encoding="utf-8")
        ast.parse(text, filename=str(path))                      # valid Python
        header = text.split("\n# %%", 1)[0]
        assert "formats: py:percent" in header and "name: python3" in header, \
            f"{path.name}: no Jupytext header naming the percent format and the python3 kernel"
        cells = re.split(r"^# %%", text, flags=re.M)[1:]
        assert cells[0].startswith(" [markdown]\n# # "), \
            f"{path.name}: the first cell must be Markdown with the page's title (# # Title)"
        code = [c for c in cells if not c.startswith(" [markdown]")]
        assert code and all(c.strip() for c in code), f"{path.name}: an empty code cell"
        # each tutorial checks its numbers against a reference (a failing assert fails the build)
        assert "assert " in text, f"{path.name}: checks nothing"


def test_api_reference_finds_every_public_module() -> None:
    gen_api = _load("gen_api")
    found = {name for name, _ in gen_api.public_modules()}
    # the reference: the package's modules as the import system walks them
    walked = {"jourdain"} | {
        m.name for m in pkgutil.walk_packages(jourdain.__path__, "jourdain.")
        if not any(part.startswith("_") for part in m.name.split("."))
    }
    assert found == walked
    pages = [gen_api.page_of(name, pkg) for name, pkg in gen_api.public_modules()]
    assert len(pages) == len(set(pages)), "two modules would share one reference page"


def test_public_values_name_their_module() -> None:
    gen_api = _load("gen_api")
    modules = gen_api.public_modules()
    row = gen_api.api_row("WORLD", jourdain.WORLD, modules)
    assert re.search(r"\| `jourdain\.[a-z_.]+` \|$", row), row
    assert gen_api.api_row("kinematics", jourdain.kinematics, modules).startswith(
        f"| [`kinematics`][{jourdain.kinematics.__module__}.kinematics]")


def test_every_example_model_has_its_gallery_text() -> None:
    gallery = _load("gen_gallery")
    paragraphs = gallery.readme_paragraphs()
    models = gallery.models()
    assert models
    missing = [m.name for m in models if m.name not in paragraphs]
    assert not missing, f"examples/README.md has no paragraph for {missing}"


def test_gallery_cuts_figures_by_their_heading(tmp_path: Path) -> None:
    gallery = _load("gen_gallery")
    report = tmp_path / "report.html"
    report.write_text(
        "<h2>4. Linearization</h2><svg id='eig'></svg>"
        "<h2>5. Simulation</h2><svg id='coords'></svg><svg id='energy'></svg>"
        "<h3>Snapshots of the motion</h3><svg id='strip'></svg>"
        "<h3>Animation</h3><svg xmlns=\"http://www.w3.org/2000/svg\" id='anim'></svg>",
        encoding="utf-8")
    figures = dict(gallery.tree_figures(report))
    assert list(figures) == ["snapshots", "animation", "simulation"]
    assert "id='strip'" in figures["snapshots"] and "id='coords'" in figures["simulation"]
    assert all('xmlns="http://www.w3.org/2000/svg"' in svg for svg in figures.values())


def _page(src_uri: str) -> Any:
    return SimpleNamespace(file=SimpleNamespace(src_uri=src_uri))


def test_hooks_point_example_links_at_the_sites_copy() -> None:
    hooks = _load("hooks")
    md = "[a](../examples/view_robot_arm.py) [b](../../examples/x.toml) [c](../src/x.py)"
    assert hooks.on_page_markdown(md, _page("viewer.md"), None, None) == \
        "[a](examples/view_robot_arm.py) [b](../../examples/x.toml) [c](../src/x.py)"
    assert hooks.on_page_markdown("[b](../../examples/x.toml)", _page("tutorials/a.md"),
                                  None, None) == "[b](../examples/x.toml)"


def test_hooks_reject_what_loads_from_the_network(caplog: pytest.LogCaptureFixture) -> None:
    hooks = _load("hooks")
    offline = '<a href="https://toml.io">TOML</a><img src="figures/x.svg"><script src="a.js">'
    with caplog.at_level(logging.WARNING):
        assert hooks.on_post_page(offline, _page("index.md"), None) == offline
    assert not caplog.records
    for remote in ('<script src="https://cdn.example/x.js"></script>',
                   '<link rel="stylesheet" href="//fonts.example/css">',
                   "<style>@import 'https://fonts.example/a.css';</style>",
                   '<img src="http://example.org/a.png">'):
        caplog.clear()
        with caplog.at_level(logging.WARNING):
            hooks.on_post_page(remote, _page("index.md"), None)
        assert len(caplog.records) == 1, remote
    # the notebook template's MathJax block is removed from tutorial pages
    mathjax = ('<!-- Load mathjax -->\n<script src="https://cdnjs.example/mathjax.js"> </script>'
               "\n<!-- End of mathjax configuration -->")
    caplog.clear()
    with caplog.at_level(logging.WARNING):
        assert hooks.on_post_page(mathjax, _page("tutorials/a.py"), None) == ""
    assert not caplog.records


def test_hooks_drop_sphinx_role_prefixes_on_reference_pages() -> None:
    hooks = _load("hooks")
    html = "Result of :func:<code>projection</code>; see :class:<code>System</code>."
    assert hooks.on_post_page(html, _page("reference/jourdain/x.md"), None) == \
        "Result of <code>projection</code>; see <code>System</code>."
    assert hooks.on_post_page(html, _page("method.md"), None) == html
