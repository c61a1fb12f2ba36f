"""What one report run knows: the record of what was written (:class:`ReportInfo`), the
names of the files of a report folder, and the context its sections share (:class:`Run`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..modelfile import ModelFile
from .figures import Figures


@dataclass
class ReportInfo:
    """What :func:`write_report` wrote: the HTML file, all files, and a short summary;
    ``status`` "complete", "interrupted" (Ctrl-C: what was computed is written) or "failed"
    (the simulation failed: the motion up to the failure is written), ``message`` why."""

    html: Path
    files: list[Path] = field(default_factory=list)
    summary_lines: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    status: str = "complete"
    message: str = ""


#: the format tag of run.json, the manifest of a report folder
RUN_FORMAT = "jourdain-run/1"


def model_copy(model: ModelFile) -> str:
    """The name of the report's copy of the model: ``model.urdf`` for a URDF robot, else
    ``model.toml``."""
    return "model.urdf" if str(model.path).lower().endswith(".urdf") else "model.toml"


def report_files(model: ModelFile) -> list[str]:
    """The names of the files :func:`write_report` writes for ``model`` (the command line
    refuses to overwrite them without ``--force``)."""
    return ["report.html", "run.json", model_copy(model), "equations.tex", "equations.json",
            "values.json", *(f"linearization-{n.name}.json" for n in model.nominal),
            "simulation.csv", *(f"wrench-{b.joint.name}.csv" for b in model.system.bodies),
            *((["loops.json", "loops.csv", "linearization-equilibrium.json",
                *(f"wrench-{c.name}.csv" for c in model.system.closing)])
              if model.system.closing else [])]




@dataclass
class Run:
    """The context of one report: the model and its options, what was written so far
    (``info``), the operation counts of the equations (``ops``), the model's summary
    (:func:`jourdain.workflow.summary`), the parameter values in use (``values``: the
    model's, with the overrides), the figures and the symbolic display (a finished
    :class:`~jourdain.io.report.equations.Display` or a worker's future of it)."""

    model: ModelFile
    out: Path
    params: dict[str, float]
    t_end: float | None
    max_ops: int
    progress: Any
    info: ReportInfo
    summ: dict[str, Any]
    values: dict[str, float]
    figures: Figures
    display: Any
    ops: dict[str, int] = field(default_factory=dict)
    #: the simulation's results (section 5), for the sections after it (a closed system's
    #: "Closed loops"); None before the simulation or where it failed at once
    results: Any = None
