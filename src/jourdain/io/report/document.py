"""The report as a whole: its sections in order, the page, ``run.json``, and the workers of
``jourdain run`` (:func:`write_report`)."""

from __future__ import annotations

import datetime as _dt
import json
import time
from collections.abc import Mapping
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

from ...numeric import build_eom_soon
from ...simulation.problem import build_integrator_soon
from ...simulation.results import mark_interrupted
from ...version import __version__
from ...workflow import has_capability, summary
from .. import export
from ..interrupted import LATE, deaf_to_ctrl_c, write_text
from ..modelfile import ModelFile
from ..workers import fork_workers, ignore_interrupt
from . import loops, rolling
from .elastic import elastic_html
from .equations import (
    Display,
    cached,
    cached_display,
    display_in_worker,
    display_key,
    equations_section,
    set_pending,
)
from .figures import Figures, prepare_worker
from .html import CSS, esc, note
from .linearization import linearization_section, nominal_placeholder
from .sections import model_section, numbers_section
from .simulation import simulation_section
from .state import RUN_FORMAT, ReportInfo, Run

#: the number of computed sections (the list of files is the sixth)
SECTIONS = 5
_EQUATIONS = "<!--jourdain-equations-->"


def compute_sections(run: Run, sections: list[str], display: Future[Display] | None) -> None:
    """The sections of the report, each appended to ``sections`` when it is complete, with
    their data files (so that an interruption leaves the sections finished before it). The
    symbolic display (section 2) is ``run.display`` (from the cache), else the worker's
    ``display``, else computed here in turn."""
    sections.append(model_section(run) + elastic_html(run))
    if run.model.system.is_general:  # velocity constraints: numbers in z, steady motions
        sections.append(rolling.equations_section(run))
        sections.append(rolling.numbers_section(run))
        sections.append(rolling.linearization_section(run))
        sections.append(simulation_section(run))
        sections.append(rolling.contacts_section(run, run.results))
        return
    if run.model.system.closing:  # a closed system: its numbers, and the loops' section
        sections.append(loops.equations_section(run))
        sections.append(numbers_section(run))
        sections.append(loops.linearization_section(run))
        sections.append(simulation_section(run))
        sections.append(loops.loops_section(run, run.results))
        return
    if run.display is None and display is None:
        run.display = cached_display(run.model, run.max_ops)
    if run.display is not None:
        html, files = equations_section(run.display, run.model, run.out)
        run.info.files += files
        sections.append(html)
    else:  # the worker's: its files are written when it is done
        run.info.files += [run.out / "equations.tex", run.out / "equations.json"]
        sections.append(_EQUATIONS)
    sections.append(numbers_section(run))
    sections.append(linearization_section(run))
    sections.append(simulation_section(run))


def write_report(model: ModelFile, out: Path, parameters: Mapping[str, float] | None = None,
                 t_end: float | None = None, max_ops: int = export.MAX_DISPLAY_OPS,
                 progress: Any = False, parallel: bool = False,
                 study: Any = None,  # study: a parameter study's section (H3)
                 figure_pool: ProcessPoolExecutor | None = None) -> ReportInfo:
    """Compute everything for ``model`` and write ``out/report.html`` with the data files.

    Files: ``report.html``, ``model.toml`` (a copy of the input; ``model.urdf`` for a URDF
    robot), ``equations.tex``,
    ``equations.json`` (the matrices with shared temporaries), ``values.json`` (the numbers at
    the initial state, the format of ``jourdain eval --json``), ``linearization-<name>.json``
    per nominal motion, ``simulation.csv`` (written as the simulation goes; ``progress`` is
    passed to it), ``run.json`` (``"format": "jourdain-run/1"``: how the run ended, ``status``
    complete, interrupted or failed, and ``message``; the files and notes).

    ``parallel``: the figures, and the symbolic display where the cache lacks it, are computed
    in a process forked from this one (at once: it imports Matplotlib meanwhile) while it
    computes the numbers (``jourdain run``, where the machine has two cores
    or more; the page is the same). One worker, not two: a second one imported Matplotlib
    again and raised the processor time of a small report by half (double pendulum, warm
    cache: 0.5 s here + 0.8 s in one worker against 0.5 s + 1.2–1.7 s in two; in-process
    1.1–1.4 s), which a shared machine pays in wall time.

    ``figure_pool``: with ``parallel``, the figures' worker forked earlier
    (``fork_workers(prepare_worker)``; ``jourdain run`` forks it before it reads the model,
    so that Matplotlib is imported while the model is read and derived, on a core that would
    otherwise wait). The display, where the cache lacks it, is then computed in a second
    worker forked here (it imports SymPy, not Matplotlib). Both are shut down here.

    ``study``: a parameter study (a study file or :class:`jourdain.study.StudySpec`) run on
    this model; its section (stability map, Campbell diagram, histograms, the outputs' table)
    follows the simulation, its files (``study.nc``, ``study-*.svg``/``.png``) join the report's
    (:func:`jourdain.study.report.study_section`; a parameter study's section, H3).

    Ctrl-C stops the work: the sections finished before it are written (a simulation stops
    where it is and its motion up to there is shown), and report.html, run.json and the header
    of simulation.csv say that the run was interrupted (``info.status``). A simulation that
    fails keeps its motion up to the failure (``info.status`` "failed").
    """
    t_start = time.perf_counter()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    system = model.system
    info = ReportInfo(out / "report.html")
    pool: ProcessPoolExecutor | None = figure_pool  # the figures' worker
    display_pool: ProcessPoolExecutor | None = None
    display: Future[Display] | None = None
    known: Display | None = None
    try:
        closed = system.is_closed  # no symbolic display of a closed or general system
        if parallel and closed and pool is None:  # the figures' worker alone
            pool = fork_workers(prepare_worker)
        if parallel and not closed:  # the display from the cache, else from a worker
            key = display_key(model, max_ops)  # derives the equations (the workers' copies)
            known = cached(key)
            if known is None or pool is None:
                set_pending(model, max_ops)
                if pool is None:  # one worker: Matplotlib imported there while this works
                    display_pool = pool = fork_workers(prepare_worker)
                else:  # the figures' worker has it: the display alone
                    display_pool = fork_workers(ignore_interrupt)
                set_pending(None, max_ops)  # the worker has its copy
            if known is None and display_pool is not None:
                display = display_pool.submit(display_in_worker, key)
        if has_capability("simulate"):  # compiled while the equations and numbers are computed
            build_integrator_soon()  # after the forks (a child would copy the build's lock)
        # System.evaluate's library compiled in a thread while the summary compiles the
        # integrator's M, k, q: two compilers side by side (robot arm, empty cache: its two
        # libraries 0.53 + 0.73 s one after the other, 0.79 s together)
        if not system.is_general:
            build_eom_soon(system)
        summ = summary(model)  # the symbolic equations and reactions
        values = system.parameter_values
        values.update(parameters or {})
        run = Run(model, out, dict(parameters or {}), t_end, max_ops, progress, info, summ,
                  values, Figures(pool), known)
        sections: list[str] = []
        try:
            compute_sections(run, sections, display)
            if study is not None:  # a parameter study's section (H3); xarray is optional
                from ...study.report import study_section

                sections.append(study_section(study, out, info, model=model.path))
        except KeyboardInterrupt:
            info.status = "interrupted"
            info.message = (f"interrupted by the user (Ctrl-C) after section {len(sections)} "
                            f"of {SECTIONS + system.is_closed}; the sections after it "
                            "are missing")
        try:
            if display is not None:  # the worker's display, and its files
                try:
                    run.display = display.result()
                except BrokenProcessPool:  # the worker's process was lost: the display here
                    run.display = cached_display(model, max_ops)
                html, _ = equations_section(run.display, model, out)
                sections = [html if s == _EQUATIONS else s for s in sections]
            page = _page(run, sections, t_start)
        except KeyboardInterrupt:  # while the figures or the display were collected
            info.status = "interrupted"
            info.message = ("interrupted by the user (Ctrl-C) while the figures and the "
                            "equations were collected; those not done by then are missing")
            run.figures.abandon()
            sections = [s.replace(_EQUATIONS, note("equations: not shown (interrupted)"))
                        for s in sections]
            page = _page(run, sections, t_start)
    finally:
        for worker in (pool, None if display_pool is pool else display_pool):
            if worker is not None:
                worker.shutdown(cancel_futures=True)
    manifest = {"format": RUN_FORMAT, "model": system.name, "file": model.path,
                "status": info.status, "message": info.message,
                "files": [f.name for f in info.files], "notes": info.notes}
    with deaf_to_ctrl_c():  # the page and the manifest whole (a few milliseconds)
        info.html.write_text(page, encoding="utf-8")
        (out / "run.json").write_text(json.dumps(manifest, indent=1), encoding="utf-8")
        if info.status == "interrupted" and (out / "simulation.csv").is_file():
            # interrupted after the simulation (its figures, a study's section): it says so too
            mark_interrupted(out / "simulation.csv", f"{info.message}; the motion is complete")
    ops = run.display.ops if run.display is not None else {}
    count = (f" with {ops['M'] + ops['k'] + ops['q']} operations"
             if all(k in ops for k in ("M", "k", "q")) else "")
    info.summary_lines.insert(0, f"{system.name}: f = {system.f}, p = {len(system.bodies)} "
                                 f"bodies, {summ['constraints']} constrained directions; "
                                 f"M·ÿ + k = q{count}"
                                 + (f"; closed by {', '.join(c.name for c in system.closing)}, "
                                    f"independent {', '.join(system.independent or ('auto',))}"
                                    if system.closing else ""))
    for n in info.notes:
        info.summary_lines.append(f"  note: {n}")
    if info.status != "complete":
        info.summary_lines.append(f"  {info.status}: {info.message}")
    return info


def _page(run: Run, sections: list[str], t_start: float) -> str:
    """The HTML page: the sections with their figures and nominal motions filled in, the list
    of files (``report.html`` and ``run.json`` first) and the header."""
    info, model = run.info, run.model
    if info.html not in info.files:  # (the page again, after an interruption)
        info.files.insert(0, info.html)
        info.files.insert(1, run.out / "run.json")
    files = "".join(f"<li><a href='{esc(f.name)}'>{esc(f.name)}</a></li>" for f in info.files)
    number = SECTIONS + 1 + model.system.is_closed  # after "Closed loops" or "Contacts"
    sections.append(f"<h2>{number}. Files</h2><ul>{files}</ul>")
    body = run.figures.fill("".join(sections))
    if run.display is not None:
        for i, nominal in enumerate(model.nominal):
            body = body.replace(nominal_placeholder(i), run.display.nominal[nominal.name], 1)
    elapsed = time.perf_counter() - t_start
    name = model.system.name
    head = (f"<h1>{esc(name)}</h1><p class='meta'>jourdain {__version__} report of "
            f"{esc(model.path)}, {_dt.datetime.now().strftime('%Y-%m-%d %H:%M')}, "
            f"computed in {elapsed:.1f} s</p>")
    if info.status != "complete":
        head += f"<p class='bad'>{esc(info.status.capitalize())}: {esc(info.message)}.</p>"
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>{esc(name)} — jourdain report</title><style>{CSS}</style></head>"
            f"<body>{head}{body}</body></html>")


def mark_report(out: Path, model: ModelFile, when: str) -> None:
    """Mark the report folder ``out`` as interrupted ``when`` (Ctrl-C after
    :func:`write_report` handled its own: while the page and run.json were written, or the
    summary printed): ``run.json``'s status, a banner on ``report.html`` (each written, with
    the files found, where the interruption left none) and ``simulation.csv``'s status."""
    out = Path(out)
    message = LATE.format(when=when)
    with deaf_to_ctrl_c():
        manifest: Any = None
        try:
            manifest = json.loads((out / "run.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            pass
        if not isinstance(manifest, dict):
            manifest = {"format": RUN_FORMAT, "model": model.system.name, "file": model.path,
                        "files": sorted(p.name for p in out.iterdir() if p.is_file()),
                        "notes": []}
        if manifest.get("status") != "interrupted":
            manifest.update(status="interrupted", message=message)
        write_text(out / "run.json", json.dumps(manifest, indent=1))
        html = out / "report.html"
        banner = f"<p class='bad'>Interrupted: {esc(message)}.</p>"
        try:
            page = html.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            page = (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
                    f"<title>{esc(model.system.name)} — jourdain report</title>"
                    f"<style>{CSS}</style></head><body><h1>{esc(model.system.name)}</h1>"
                    "</body></html>")
        if "<p class='bad'>Interrupted:" not in page:
            at = page.find("</h1>")
            at = at + 5 if at >= 0 else 0
            page = page[:at] + banner + page[at:]
        write_text(html, page)
        if (out / "simulation.csv").is_file():
            mark_interrupted(out / "simulation.csv", message)
