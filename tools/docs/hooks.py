"""MkDocs hooks of the documentation site (mkdocs.yml ``hooks:``).

* Links from a page under docs/ to a file of the repository's examples/ folder
  (``../examples/view_robot_arm.py``, right on GitHub) point at the copy that
  tools/docs/gen_pages.py puts into the site (``examples/view_robot_arm.py``).
* The navigation files of mkdocs-literate-nav (``SUMMARY.md`` of the generated reference and
  gallery) are read for the navigation only, not built as pages of their own.
* The docstrings use Sphinx roles (``:func:`projection` ``); Markdown renders the name as code
  and leaves the role's prefix as text, which the reference pages drop.
* The site must load nothing from the network. The notebook template of mkdocs-jupyter adds
  MathJax and Mermaid from a CDN to every tutorial page; the tutorials use neither (no LaTeX
  output, no diagrams), so both blocks are removed. Any other script, style sheet, font or
  image that a page would load from ``http(s)://`` is logged as a warning, which
  ``mkdocs build --strict`` turns into a failed build.
"""

from __future__ import annotations

import logging
import posixpath
import re
from typing import Any

log = logging.getLogger("mkdocs.hooks.jourdain")

# a Markdown link or image target that leaves docs/ for the repository's examples/ folder
_EXAMPLE_LINK = re.compile(r"\]\((?P<up>(?:\.\./)+)examples/(?P<rest>[^)\s]+)\)")

# the two CDN blocks of mkdocs-jupyter's notebook template (nbconvert's mathjax and
# mermaid_js macros), matched by the comments and the module script they consist of
_MATHJAX = re.compile(r"<!-- Load mathjax -->.*?<!-- End of mathjax configuration -->", re.S)
_MERMAID = re.compile(r"<script type=\"module\">(?:(?!</script>).)*?mermaid(?:(?!</script>).)*?"
                      r"</script>", re.S)

# a Sphinx role's prefix left in front of the code it marked (":func:<code>x</code>")
_ROLE = re.compile(r":(?:py:)?(?:func|class|mod|meth|attr|data|exc|obj|const):(?=<code>)")

# what makes a browser fetch a resource (not a plain hyperlink, which is fine)
_REMOTE_LOAD = re.compile(
    r"""<(?:script|img|iframe|source|audio|video)\b[^>]*\bsrc\s*=\s*["']?(?:https?:)?//"""
    r"""|<link\b[^>]*\bhref\s*=\s*["']?(?:https?:)?//"""
    r"""|url\(\s*["']?(?:https?:)?//"""
    r"""|@import\s+["'](?:https?:)?//"""
    r"""|import\(\s*["'](?:https?:)?//""",
    re.I,
)


def on_nav(nav: Any, config: Any, files: Any) -> Any:
    """Leave the literate-nav files (read by then) out of the build."""
    from mkdocs.structure.files import InclusionLevel  # the build's own package

    for file in files.documentation_pages():
        if file.src_uri.endswith("/SUMMARY.md"):
            file.inclusion = InclusionLevel.EXCLUDED
    return nav


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """Re-point links to ``../examples/<file>`` at the site's copy of the example file."""
    depth = page.file.src_uri.count("/")

    def repl(m: re.Match[str]) -> str:
        ups = m.group("up").count("../")
        if ups != depth + 1:           # not the repository's examples/ folder: leave it
            return m.group(0)
        target = posixpath.join(*([".."] * depth), "examples", m.group("rest"))
        return f"]({target})"

    return _EXAMPLE_LINK.sub(repl, markdown)


def on_post_page(output: str, page: Any, config: Any) -> str:
    """Remove the notebook template's CDN blocks; warn about anything else loaded remotely."""
    if page.file.src_uri.startswith("tutorials/"):
        output = _MATHJAX.sub("", output)
        output = _MERMAID.sub("", output)
    if page.file.src_uri.startswith("reference/"):
        output = _ROLE.sub("", output)
    for m in _REMOTE_LOAD.finditer(output):
        start = max(0, m.start() - 60)
        log.warning("%s: loads a resource from the network (the site must build and work "
                    "offline): ...%s...", page.file.src_uri,
                    output[start:m.end() + 60].replace("\n", " "))
    return output
