"""A study in HTML: a section of the model's report (``jourdain run MODEL --study STUDY``) and
the study's own page (``jourdain study --plots DIR``).

:func:`study_section` runs a study on the report's model, writes its dataset (``study.nc``)
and its figures (``study-<name>.svg``/``.png``: the stability map and Campbell diagram of a
grid with eigenvalues, histograms of the scalar outputs of list and random designs) into the
report's folder, and returns the section: what was varied and computed, a table of every
scalar output (min, mean, max, cases) and the verdict counts read from the dataset, the figures
inline (each linked to its file) and the failed cases. :func:`study_page` writes the same
content as a page of its own.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import JourdainError
from .linear import VERDICTS
from .plots import study_plots

__all__ = ["output_summary", "study_page", "study_section"]

#: failed cases listed by name (the rest counted)
MAX_FAILED_LISTED = 50


def output_summary(ds: Any) -> list[tuple[str, str, float, float, float, int]]:
    """``(name, units, min, mean, max, cases)`` of every scalar floating output of a study's
    dataset (one value per case; failed cases, NaN, left out)."""
    lead = ds["error"].dims
    rows = []
    for name in ds.data_vars:
        v = ds[name]
        if v.dims != lead or v.dtype.kind != "f":
            continue
        vals = v.values[np.isfinite(v.values)]
        if vals.size:
            rows.append((str(name), str(v.attrs.get("units", "")), float(vals.min()),
                         float(vals.mean()), float(vals.max()), int(vals.size)))
    return rows


def _summary_html(ds: Any) -> str:
    esc = html.escape
    rows = [f"<tr><th>{esc(n)}</th><td>{esc(u)}</td><td>{lo:.6g}</td><td>{mean:.6g}</td>"
            f"<td>{hi:.6g}</td><td>{k}</td></tr>" for n, u, lo, mean, hi, k in output_summary(ds)]
    if "verdict" in ds:
        counts = ", ".join(f"{esc(w)}: {int((ds.verdict.values == i).sum())}"
                           for i, w in enumerate(VERDICTS))
        rows.append(f"<tr><th>verdict</th><td colspan='5'>{counts}</td></tr>")
    return ("<table><tr><th>output</th><th>unit</th><th>min</th><th>mean</th><th>max</th>"
            f"<th>cases</th></tr>{''.join(rows)}</table>")


def _failed_html(ds: Any, tag: str) -> str:
    esc = html.escape
    err = ds["error"].values.reshape(-1)
    bad = np.flatnonzero(err != "")
    items = "".join(f"<li>case {int(i)}: {esc(str(err[i]))}</li>"
                    for i in bad[:MAX_FAILED_LISTED])
    if bad.size > MAX_FAILED_LISTED:
        items += f"<li>… {bad.size - MAX_FAILED_LISTED} more</li>"
    return f"<{tag}>Failed cases ({bad.size})</{tag}>" + (f"<ul>{items}</ul>" if items else "")


def _figures_html(paths: list[Path]) -> str:
    """The SVG figures inline (the page stays self-contained), each linked to its file."""
    esc = html.escape
    out = []
    for p in paths:
        if p.suffix != ".svg":
            continue
        text = p.read_text(encoding="utf-8")
        text = text[text.index("<svg"):]
        png = p.with_suffix(".png")
        out.append(f"<figure>{text}<figcaption>{esc(p.stem)}: <a href='{esc(p.name)}'>SVG"
                   f"</a>, <a href='{esc(png.name)}'>PNG</a></figcaption></figure>")
    return "".join(out)


def _describe(spec: Any, ds: Any) -> str:
    """The design, the varied quantities with their ranges (from the dataset) and what was
    computed."""
    esc = html.escape
    seed = f", seed {spec.seed}" if spec.design == "random" else ""
    varied = []
    for v in spec.varied:
        vals = np.asarray(ds[v.name].values, dtype=float)
        what = {"parameter": "", "y0": " (initial)", "yd0": " (initial rate)"}[v.kind]
        how = (f" {v.distribution}{tuple(v.arguments)}" if v.distribution else "")
        varied.append(f"{v.name}{what}{how} from {vals.min():.6g} to {vals.max():.6g}")
    return (f"<p>{esc(spec.design)} design of {spec.n_cases} cases{esc(seed)} on "
            f"{esc(str(ds.attrs.get('model', '')))}; varied: "
            f"{esc('; '.join(varied) or 'nothing')}; computed: "
            f"{esc(', '.join(sorted(spec.compute)))}.</p>")


def study_section(study: Any, out: str | Path, info: Any = None, *, model: Any = None,
                  workers: int | None = None, quiet: bool = True) -> str:
    """Run ``study`` (a :class:`~jourdain.study.spec.StudySpec` or a study file; ``model``
    replaces its model file) and return its section of the report in ``out``.

    Writes ``out/study.nc`` and ``out/study-<figure>.svg``/``.png``; with ``info`` (the
    report's :class:`~jourdain.io.report.ReportInfo`), adds them to its files and a failure
    of the study to its notes (the section then says what went wrong; the report goes on).
    """
    from .reader import load_study
    from .runner import run_study

    out = Path(out)
    esc = html.escape
    try:
        spec = study if not isinstance(study, str | Path) else load_study(study, model=model)
        ds = run_study(spec, out / "study.nc", workers=workers, quiet=quiet, force=True)
        paths = study_plots(ds, out, prefix="study-")
    except (JourdainError, OSError, ImportError) as exc:
        msg = f"the study could not be run: {exc}"
        if info is not None:
            info.notes.append(msg)
        return f"<h2>Parameter study</h2><p class='bad'>{esc(msg)}</p>"
    if info is not None:
        info.files += [out / "study.nc", *paths]
        failed = int(ds.attrs.get("n_failed", 0))
        line = f"  study {spec.name}: {spec.n_cases} cases ({spec.design})"
        if "verdict" in ds:
            line += f", {int((ds.verdict.values == 2).sum())} unstable"
        getattr(info, "summary_lines", []).append(
            line + (f", {failed} failed" if failed else "") + "; results in study.nc")
    title = esc(str(spec.name))
    return (f"<h2 id='study'>Parameter study: {title}</h2>{_describe(spec, ds)}"
            f"<h3>Outputs</h3>{_summary_html(ds)}{_figures_html(paths)}"
            f"{_failed_html(ds, 'h3')}"
            f"<p>Results: <a href='study.nc'>study.nc</a> (NetCDF; "
            f"<code>xarray.open_dataset</code>).</p>")


def study_page(ds: Any, folder: str | Path) -> Path:
    """Write the study's plots (:func:`~jourdain.study.plots.study_plots`) and ``index.html``
    beside them: one self-contained page with the study's attributes, the plots (inline SVG),
    a summary of every scalar output and the failed cases. Returns the page's path."""
    esc = html.escape
    folder = Path(folder)
    paths = study_plots(ds, folder)
    rows = "".join(f"<tr><th>{esc(str(k))}</th><td>{esc(str(v))[:300]}</td></tr>"
                   for k, v in ds.attrs.items() if k != "study_file")
    title = esc(str(ds.attrs.get("title", "study")))
    page = f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:auto}}th{{text-align:left}}
td,th{{padding:2px 8px}}figure{{display:inline-block;margin:1em}}</style></head><body>
<h1>{title}</h1>
<table>{rows}</table>
<h2>Outputs</h2>
{_summary_html(ds)}
{_figures_html(paths)}
{_failed_html(ds, "h2")}
<h2>Study file</h2><pre>{esc(str(ds.attrs.get("study_file", "")))}</pre>
</body></html>
"""
    out = folder / "index.html"
    out.write_text(page, encoding="utf-8")
    return out
