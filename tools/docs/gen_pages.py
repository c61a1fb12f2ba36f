"""Pages and files the site takes from outside docs/ (mkdocs-gen-files script, run by
``mkdocs build``; nothing it writes lands in the repository).

* ``contributing.md`` and ``changelog.md``: CONTRIBUTING.md and CHANGELOG.md of the repository.
  Their links are written for the repository (``docs/method.md``); on the site a link into
  docs/ points at the page, a link to any other file of the repository becomes its path in code
  type (the site has no copy of the sources), so strict mode has nothing to reject.
* ``examples/``: every example file (models, URDF, scripts, study files) for download; the
  pages' links to ``../examples/<file>`` are pointed at these by tools/docs/hooks.py.
"""

from __future__ import annotations

import re
from pathlib import Path

import mkdocs_gen_files

ROOT = Path(__file__).resolve().parents[2]

# the repository's files that are pages of the site, by their path in the repository
PAGES = {"CONTRIBUTING.md": "contributing.md", "CHANGELOG.md": "changelog.md"}

_LINK = re.compile(r"(?<!!)\[(?P<text>[^\]]+)\]\((?P<target>[^)\s]+)\)")


def _site_links(markdown: str) -> str:
    def repl(m: re.Match[str]) -> str:
        text, target = m.group("text"), m.group("target")
        if re.match(r"[a-z]+:|#", target):                 # web address, mail, anchor
            return m.group(0)
        path, _, anchor = target.partition("#")
        if path in PAGES:
            return f"[{text}]({PAGES[path]}{'#' + anchor if anchor else ''})"
        if path.startswith("docs/") and path.endswith(".md"):
            return f"[{text}]({path[len('docs/'):]}{'#' + anchor if anchor else ''})"
        if text.startswith("`"):
            return text
        return f"{text} (`{path}`)"
    return _LINK.sub(repl, markdown)


for source, page in PAGES.items():
    with mkdocs_gen_files.open(page, "w") as f:
        f.write(_site_links((ROOT / source).read_text(encoding="utf-8")))

for path in sorted((ROOT / "examples").rglob("*")):
    if path.is_file() and path.suffix != ".md" and "__pycache__" not in path.parts:
        with mkdocs_gen_files.open(path.relative_to(ROOT).as_posix(), "wb") as f:
            f.write(path.read_bytes())
