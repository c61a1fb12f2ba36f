"""The report of ``jourdain run``: one self-contained HTML file plus the data files.

Equations are MathML (browsers render it natively, no script, no network), matrices at the
initial state are tables, plots are inline SVG, the motion is a strip of snapshots and an SVG
animation (SMIL). Every part that a stage cannot deliver (a capability missing, a singular
position, ...) becomes a note in the report instead of stopping the others.

Modules: :mod:`~.document` (:func:`write_report`: the sections in order, the page,
``run.json``), :mod:`~.state` (:class:`ReportInfo`, the files of a report folder),
:mod:`~.sections` (the model; the numbers at the initial state), :mod:`~.equations` (the
symbolic display, cached), :mod:`~.linearization`, :mod:`~.simulation`, :mod:`~.figures`
(Matplotlib plots as SVG, drawn here or in a worker), :mod:`~.motion` (positions along the
motion and the animation), :mod:`~.html` (escaping, tables, MathML symbols, the style sheet)
and :mod:`~.workers` (the forked workers of ``jourdain run``). The workflow shared with the
command line is :mod:`jourdain.workflow`.
"""

from .document import mark_report, write_report
from .equations import MAX_DISPLAY_ROWS, REPORT_SIMPLIFY_SECONDS
from .linearization import floquet_html as _floquet_html
from .simulation import wrench_section as _wrench_section
from .state import RUN_FORMAT, ReportInfo, model_copy, report_files

__all__ = ["write_report", "mark_report", "ReportInfo", "RUN_FORMAT", "model_copy",
           "report_files",
           "MAX_DISPLAY_ROWS", "REPORT_SIMPLIFY_SECONDS", "_floquet_html",
           "_wrench_section"]
