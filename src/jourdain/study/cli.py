"""``jourdain study``: run a study file on this machine's cores or on a Dask cluster."""

from __future__ import annotations

import argparse
import time
from typing import Any

EXAMPLE = ("jourdain study --spec examples/studies/rotor_stability_map.toml --out map.nc "
           "--plots plots/\n  jourdain study --spec examples/studies/rotor_critical_speed.toml "
           "--scheduler tcp://10.0.0.5:8786")


def add_study_parser(subs: Any, parser_class: type) -> Any:
    """Add the ``study`` subcommand to the CLI's subparsers."""
    help = ("run a parameter study (grid, list or Monte-Carlo samples; evaluate, linearize, "
            "simulate, critical values) and write its results to NetCDF (docs/studies.md)")
    p = subs.add_parser("study", help=help, description=help, epilog=f"example:\n  {EXAMPLE}",
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model", metavar="MODEL", nargs="?",
                   help="model file (default: the study file's [study] model)")
    p.add_argument("--spec", required=True, metavar="STUDY",
                   help="the study file (TOML, see docs/studies.md)")
    p.add_argument("--out", metavar="FILE",
                   help="NetCDF file of the results (.nc); finished blocks are saved in "
                        "FILE.parts/ as they come and a run with the same --out resumes")
    p.add_argument("--workers", type=_workers, metavar="N",
                   help="processes on this machine (default: one per core; 1: no processes)")
    p.add_argument("--pool", choices=("auto", "processes", "threads"), default="auto",
                   help="how the local workers run: processes, threads (for work that "
                        "releases the GIL), or auto (the default: threads, unless the study "
                        "simulates case by case (ensemble = false, SciPy methods): processes)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on this dask.distributed scheduler (tcp://host:8786)")
    p.add_argument("--plots", metavar="DIR",
                   help="write the study's plots there (stability map, Campbell diagram, "
                        "histograms) as SVG and PNG, and index.html: a page with the "
                        "study, its plots, a summary of the outputs and the failed cases")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--force", action="store_true",
                   help="replace an existing --out file and the saved parts of another study")
    p.set_defaults(func=cmd_study)
    return p


def _workers(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if n < 1:
        raise argparse.ArgumentTypeError(f"expected 1 or more workers, got {n}")
    return n


def cmd_study(args: argparse.Namespace) -> int:
    from . import load_study, run_study
    from .report import study_page

    spec = load_study(args.spec, model=args.model)
    started = time.time()
    try:
        return _study(args, spec, study_page, run_study)
    except KeyboardInterrupt:  # Ctrl-C: the files written so far say so
        mark_study(args.out, args.plots, started)
        raise


def _study(args: argparse.Namespace, spec: Any, study_page: Any, run_study: Any) -> int:
    t0 = time.perf_counter()
    ds = run_study(spec, args.out, workers=args.workers, scheduler=args.scheduler,
                   quiet=args.quiet, force=args.force, pool=args.pool, force_name="--force")
    wall = time.perf_counter() - t0
    failed = int(ds.attrs["n_failed"])
    where = f" on {args.scheduler}" if args.scheduler else ""
    print(f"study {spec.name}: {spec.n_cases} cases ({spec.design}{where}) in {wall:.2f} s"
          + (f", {failed} failed (see the error variable)" if failed else ""))
    if args.out:
        print(f"results: {args.out}")
    if args.plots:
        print(f"report: {study_page(ds, args.plots)}")
    return 0


def mark_study(out: str | None, plots: str | None, started: float) -> None:
    """The files of a study interrupted by Ctrl-C say so: the saved parts' manifest (how many
    blocks are kept; the same command resumes from them), and the NetCDF file and the plots'
    index.html where this run wrote them (modified since ``started``, a ``time.time()``)."""
    import json
    from pathlib import Path

    from ..io.interrupted import deaf_to_ctrl_c, write_text

    message = "interrupted by the user (Ctrl-C)"
    with deaf_to_ctrl_c():
        parts = Path(f"{out}.parts") if out else None
        if parts is not None and (parts / "manifest.json").is_file():
            try:
                manifest = json.loads((parts / "manifest.json").read_text())
            except (OSError, ValueError):
                manifest = None
            if isinstance(manifest, dict):
                blocks = len(list(parts.glob("block-*.npz")))
                manifest.update(status="interrupted", message=(
                    f"{message}; {blocks} blocks of {manifest.get('n_cases', '?')} cases saved "
                    "here: the same command resumes from them"))
                write_text(parts / "manifest.json", json.dumps(manifest, indent=1))
        if out and _since(Path(out), started):
            from ..simulation.results.files import h5_file

            try:  # NetCDF-4 is HDF5: a global attribute
                with h5_file(out, "r+") as h:
                    h.attrs["status"] = "interrupted"
                    h.attrs["message"] = f"{message} after these results were written"
            except OSError:
                pass
        page = Path(plots) / "index.html" if plots else None
        if page is not None and _since(page, started):
            text = page.read_text(encoding="utf-8")
            if "Interrupted:" not in text:
                at = text.find("</h1>")
                text = (text[:at + 5] + f"<p><b>Interrupted:</b> {message}; the plots may be "
                        "incomplete.</p>" + text[at + 5:]) if at >= 0 else text
                write_text(page, text)


def _since(path: Any, started: float) -> bool:
    try:
        return bool(path.is_file() and path.stat().st_mtime >= started - 1.0)
    except OSError:
        return False
