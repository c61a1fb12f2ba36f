"""The gallery of the examples (mkdocs-gen-files script, run by ``mkdocs build``).

Every model of examples/ (``*.toml`` and ``*.urdf``) is run as a user runs it,
``jourdain run examples/<model> --out <dir>``, at every build; the pictures of the gallery are
the report's own: the snapshot strip, the animation and the first time plot of a tree model's
``report.html`` (inline SVG, cut out by the section heading above each), and the PNG plots of
a closed-loop model's report. The report itself is copied into the site (gallery/reports/<stem>/). A model
whose run fails, or whose report has no picture, fails the build with the command's output.

The text of a page is the model's paragraph in examples/README.md (else the file's
``[model] description``), the command, and the model file.

mkdocs-gen-files runs this file with ``runpy.run_path`` (``__name__ == "<run_path>"``); imported
(tests/test_docs_site.py) it only defines its functions.

Environment: ``JOURDAIN_DOCS_WORKERS`` (default: the number of CPUs, at most 4) runs that
many reports at a time; the compiled libraries go to ``$JOURDAIN_CACHE`` as for any run.
"""

from __future__ import annotations

import html
import logging
import os
import re
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
# the jourdain command of the interpreter that runs mkdocs (the project's .venv)
JOURDAIN = Path(sys.executable).with_name("jourdain")

log = logging.getLogger("mkdocs.plugins.jourdain.gallery")

# the sections of a tree model's report whose first picture the gallery shows, in this order
TREE_FIGURES = (("Snapshots of the motion", "snapshots"), ("Animation", "animation"),
                ("Simulation", "simulation"))
# the plots of a closed-loop model's report (index.html), in this order
LOOP_FIGURES = ("coordinates.png", "constraint_residual.png", "reactions.png", "energy.png")

_SVG = re.compile(r"<svg\b.*?</svg>", re.S)
_HEADING = re.compile(r"<h([23])\b[^>]*>(.*?)</h\1>", re.S)
_TAG = re.compile(r"<[^>]+>")


def models() -> list[Path]:
    return sorted([*EXAMPLES.glob("*.toml"), *EXAMPLES.glob("*.urdf")])


def run_report(model: Path, out: Path) -> Path:
    """``jourdain run`` on one example; raises with the command's output when it fails."""
    cmd = [str(JOURDAIN), "run", str(model.relative_to(ROOT)), "--out", str(out), "--force"]
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"gallery: `{' '.join(cmd[1:])}` failed (exit {proc.returncode}):\n"
                           f"{proc.stdout}\n{proc.stderr}")
    return out


def readme_paragraphs() -> dict[str, str]:
    """The paragraph of examples/README.md about each file, by file name."""
    text = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    found = {}
    for para in re.split(r"\n\s*\n", text):
        m = re.match(r"\*\*`([^`]+)`\*\*(?:\s*\([^)]*\))?\s*—\s*(.*)", para, re.S)
        if m:
            found[m.group(1)] = m.group(2).strip()
    return found


def site_links(markdown: str) -> str:
    """README links (relative to examples/) made relative to a gallery page (gallery/x.md)."""
    def repl(m: re.Match[str]) -> str:
        text, target = m.group(1), m.group(2)
        if target.startswith("../docs/"):
            return f"[{text}](../{target[len('../docs/'):]})"
        if re.match(r"[a-z]+:|#", target):
            return m.group(0)
        return text
    return re.sub(r"\[([^\]]+)\]\(([^)\s]+)\)", repl, markdown)


def tree_figures(report: Path) -> list[tuple[str, str]]:
    """(name, SVG text) of the first picture right under each of TREE_FIGURES' headings."""
    text = report.read_text(encoding="utf-8")
    headings = [(m.start(), html.unescape(_TAG.sub("", m.group(2))).strip())
                for m in _HEADING.finditer(text)]
    figures: dict[str, str] = {}
    for svg in _SVG.finditer(text):
        above = [title for pos, title in headings if pos < svg.start()][-1:]
        for title, name in TREE_FIGURES:
            if name not in figures and above and title in above[0]:
                body = svg.group(0)
                if "xmlns=" not in body[:400]:
                    body = body.replace("<svg", '<svg xmlns="http://www.w3.org/2000/svg"', 1)
                figures[name] = body
                break
    return [(name, figures[name]) for _, name in TREE_FIGURES if name in figures]


def model_title(model: Path) -> tuple[str, str]:
    """The model's name and description from its file (a URDF: its robot name)."""
    if model.suffix == ".toml":
        with model.open("rb") as f:
            table = tomllib.load(f).get("model", {})
        return str(table.get("name", model.stem)), str(table.get("description", ""))
    m = re.search(r"<robot\s+name=\"([^\"]+)\"", model.read_text(encoding="utf-8"))
    return (m.group(1) if m else model.stem), ""


def write_page(gen: Any, model: Path, out: Path, about: str) -> tuple[str, str, str]:
    """gallery/<stem>.md and its pictures, written with ``gen`` (mkdocs_gen_files); returns
    (title, page, thumbnail) for the index: the animation where the report has one."""
    stem = model.stem
    title, description = model_title(model)
    text = site_links(about or description)
    lines = [f"# {title}", "", text[:1].upper() + text[1:], "",
             "```sh", f"jourdain run examples/{model.name} --out report/", "```", ""]
    pictures: list[tuple[str, str]] = []        # (caption, file relative to gallery/)
    if (out / "report.html").is_file():
        report = "report.html"
        for name, svg in tree_figures(out / "report.html"):
            rel = f"figures/{stem}/{name}.svg"
            with gen.open(f"gallery/{rel}", "w") as f:
                f.write(svg)
            pictures.append((name, rel))
    else:
        report = "index.html"
        for name in LOOP_FIGURES:
            if (out / name).is_file():
                pictures.append((Path(name).stem.replace("_", " "), f"reports/{stem}/{name}"))
    if not pictures:
        raise RuntimeError(f"gallery: the report of examples/{model.name} in {out} has no "
                           f"picture the gallery knows (headings {TREE_FIGURES} or files "
                           f"{LOOP_FIGURES}): has the report's layout changed?")
    # the report in gallery/reports/<stem>/, with the files its page loads (pictures; not the
    # data files); not beside the page, whose own index.html is gallery/<stem>/index.html
    for path in sorted(out.iterdir()):
        if path.suffix in (".html", ".png", ".svg"):
            with gen.open(f"gallery/reports/{stem}/{path.name}", "wb") as f:
                f.write(path.read_bytes())
    for caption, rel in pictures:
        lines += [f"![{caption}]({rel})", ""]
    lines += [f"[The full report](reports/{stem}/{report}) · "
              f"[the model file](../examples/{model.name})", "",
              f'??? note "examples/{model.name}"', "",
              "    ```" + ("toml" if model.suffix == ".toml" else "xml")]
    lines += ["    " + line if line else "" for line in
              model.read_text(encoding="utf-8").splitlines()]
    lines += ["    ```", ""]
    with gen.open(f"gallery/{stem}.md", "w") as f:
        f.write("\n".join(lines))
    thumbnail = next((rel for name, rel in pictures if name == "animation"), pictures[0][1])
    return title, f"{stem}.md", thumbnail


def main() -> None:
    import mkdocs_gen_files as gen  # the documentation build's own dependency

    paragraphs = readme_paragraphs()
    workers = int(os.environ.get("JOURDAIN_DOCS_WORKERS", min(4, os.cpu_count() or 1)))
    with tempfile.TemporaryDirectory(prefix="jourdain-gallery-") as tmp:
        jobs = [(model, Path(tmp) / model.stem) for model in models()]
        start = time.perf_counter()
        with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
            outs = list(pool.map(lambda job: run_report(*job), jobs))
        log.info("gallery: %d reports by `jourdain run` in %.1f s (%d at a time)", len(jobs),
                 time.perf_counter() - start, max(1, workers))
        entries = [write_page(gen, model, out, paragraphs.get(model.name, ""))
                   for (model, _), out in zip(jobs, outs, strict=True)]
    index = ["# Gallery", "",
             "Every model of the repository's `examples/` folder, run at each build of this site",
             "with `jourdain run examples/<model> --out report/`: the pictures are the report's.",
             "", '<div class="grid cards" markdown>', ""]
    for title, page, thumb in entries:
        index += [f"-   [**{title}**]({page})", "",
                  f"    [![{title}]({thumb}){{ style=\"max-height: 12rem\" }}]({page})", ""]
    index += ["</div>", ""]
    with gen.open("gallery/index.md", "w") as f:
        f.write("\n".join(index))
    with gen.open("gallery/SUMMARY.md", "w") as f:
        f.write("* [Gallery](index.md)\n")
        f.writelines(f"* [{title}]({page})\n" for title, page, _ in entries)


if __name__ in ("__main__", "<run_path>"):
    main()
