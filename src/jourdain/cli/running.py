"""``jourdain simulate``, ``jourdain run`` (the report) and ``jourdain fmu``: the motion, the
report of everything, and the FMU export."""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from ..errors import JourdainError
from ..io import capabilities as integration
from ..io.fmu import export_fmu
from ..io.interrupted import mark_results
from ..io.report import mark_report, write_report
from ..io.report.figures import prepare_worker
from ..io.workers import fork_workers, stop_workers
from ..simulation.simulate import OUTPUT_SUFFIXES
from ..workflow import require
from .arguments import UsageError, load, overrides, sim_options
from .outputs import output_file, output_folder, progress_printer, samples

EXIT_OK, EXIT_MODEL, EXIT_INTERRUPTED = 0, 1, 130


def cmd_simulate(args: argparse.Namespace) -> int:
    model = load(args.model)
    system = model.system
    require(system, "simulate", "simulation")

    # every option and the output file are checked before the work
    params = overrides(system, args.set)
    opts = sim_options(model, args)
    out = output_file(args.out, args.force, OUTPUT_SUFFIXES) if args.out else None
    try:
        return _simulate(args, model, params, opts, out)
    except KeyboardInterrupt:  # after the run's own handling: the file says so too
        mark_results(out, "after the run, as its results were saved or shown")
        raise


def _simulate(args: argparse.Namespace, model: Any, params: dict[str, float],
              opts: dict[str, Any], out: Path | None) -> int:
    system = model.system
    progress = progress_printer(args.progress, f"simulating {system.name}")
    failure: JourdainError | None = None
    try:
        # with --out the results are written as the run goes (a closed system's: at its end),
        # and complete at its end
        res = integration.simulate(model, params, **opts, progress=progress or False,
                                   output=out)
    except JourdainError as exc:
        partial = getattr(exc, "results", None)  # the motion up to a failure
        if partial is None:
            raise
        if len(partial.t) == 0:  # failed before the first sample
            raise JourdainError(f"{exc}; nothing was computed"
                                + (f" ({out} holds the header only)" if out else "")) from None
        res, failure = partial, exc
    finally:
        if progress:
            progress.done()
    names = system.coordinate_names
    span = f"t = {res.t[0]:g} … {res.t[-1]:g}"
    if out:
        print(f"wrote {out} ({samples(len(res.t))}, {span}"
              + ("" if res.status == "finished" else f"; {res.status}") + ")")
    else:
        print(f"{system.name}: simulated {span} ({samples(len(res.t))})")
    if res.constraints is not None:  # closing joints' or contacts' rows
        phi, phid = res.closure_residual
        print(f"  residuals along the run: max |Φ| = {phi:.3e}, max |Φ̇| (A·ẏ + a) = "
              f"{phid:.3e}")
    where = ("final {}: " if res.status == "finished" else f"{{}} at t = {res.t[-1]:g}: ").format
    print(where("state") + ", ".join(f"{n}={v:.6g}" for n, v in
                                     zip(names, res.y[-1], strict=True)))
    print(where("rates") + ", ".join(f"{n}_d={v:.6g}" for n, v in
                                     zip(names, res.yd[-1], strict=True)))
    kept = (f"the motion up to t = {res.t[-1]:g} ({samples(len(res.t))}) is in {out}" if out
            else "give --out FILE to keep the motion up to there")
    if failure is not None:
        raise JourdainError(f"{failure}; {kept}")
    if res.interrupted:
        print(f"jourdain simulate: interrupted (Ctrl-C) at t = {res.t[-1]:g}; {kept}",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    return EXIT_OK


def cmd_run(args: argparse.Namespace) -> int:
    # the figures' worker, forked before the model is read: it imports Matplotlib on a core
    # that would otherwise wait while this process reads and derives the model (a URDF robot:
    # yourdfpy and trimesh, 0.4 s); the report shuts it down
    pool = fork_workers(prepare_worker)
    try:
        code = _run(args, pool)
    except BaseException:  # the message at once, not after the worker's imports
        if pool is not None:
            stop_workers(pool)
        raise
    if pool is not None:  # the report's, done already
        pool.shutdown(cancel_futures=True)
    return code


def _run(args: argparse.Namespace, pool: ProcessPoolExecutor | None) -> int:
    model = load(args.model)
    params = overrides(model.system, args.set)
    opts = sim_options(model, args)
    out = output_folder(args.out, args.force, model)
    study = None
    if getattr(args, "study", None):  # a parameter study's section (H3): checked before the run
        from ..study import load_study

        study = load_study(args.study, model=model.path)
    progress = progress_printer(args.progress, f"simulating {model.system.name}")
    try:
        info = _report(args, model, out, params, opts, study, pool, progress)
    except KeyboardInterrupt:  # after the report's own handling: its files say so too
        mark_report(out, model, "as the report was written or shown")
        raise
    if info.status == "interrupted":
        print(f"jourdain run: {info.message}; the report holds what was computed",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    if info.status == "failed":
        print(f"jourdain run: error: {info.message}", file=sys.stderr)
        return EXIT_MODEL
    return EXIT_OK


def _report(args: argparse.Namespace, model: Any, out: Path, params: dict[str, float],
            opts: dict[str, Any], study: Any, pool: ProcessPoolExecutor | None,
            progress: Any) -> Any:
    """The report (:func:`write_report`) and its summary on the terminal."""
    try:
        info = write_report(model, out, parameters=params, t_end=opts.get("t_end"),
                            max_ops=args.max_ops, progress=progress or False,
                            parallel=True, study=study, figure_pool=pool)
    finally:
        if progress:
            progress.done()
    for line in info.summary_lines:
        print(line)
    print(f"report: {info.html}")
    return info


def cmd_fmu(args: argparse.Namespace) -> int:
    """``jourdain fmu MODEL --out model.fmu``: an FMI 2.0 FMU (docs/fmu.md)."""
    out = Path(args.out)
    if out.suffix.lower() != ".fmu":
        raise UsageError(f"--out: expected a file name ending in .fmu, got {args.out!r}")
    if out.is_dir():
        raise UsageError(f"--out: {args.out} is a folder; expected a .fmu file")
    if out.exists() and not args.force:
        raise UsageError(f"--out: {args.out} exists; --force replaces it")
    model = load(args.model)
    params = overrides(model.system, args.set)
    names = [n.strip() for r in args.reaction for n in r.split(",") if n.strip()]
    info = export_fmu(model, out, reactions="all" if names == ["all"] else names,
                      parameters=params, model_identifier=args.identifier,
                      binary=not args.sources_only)
    closed = (f" (independent {', '.join(info.independent)}; the dependent coordinates and "
              "the closure residuals are outputs)") if info.independent else ""
    print(f"{info.path}: FMI 2.0 model exchange and co-simulation, modelIdentifier "
          f"{info.model_identifier}; {info.states} states{closed}, "
          f"{len(model.system.parameters)} parameters, "
          f"{len(model.system.inputs)} inputs, {len(info.reactions)} reaction outputs; "
          + (f"binary {info.binary}" if info.binary else "sources only"))
    return EXIT_OK

