"""The argument parser of ``jourdain``: one subcommand per task, each with ``--help`` and an
example; a malformed argument exits with status 2."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any, NoReturn

from ..errors import shorten_words
from ..io.capabilities import SIM_METHODS
from ..simulation import simulate as sim
from ..study.cli import add_study_parser
from ..version import __version__
from ..workflow import EVAL_FORMAT
from .model_commands import cmd_check, cmd_eom
from .numbers import cmd_eval, cmd_linearize, cmd_reactions
from .outputs import PROGRESS_SECONDS
from .running import cmd_fmu, cmd_run, cmd_simulate

EXIT_USAGE = 2


class Parser(argparse.ArgumentParser):
    """argparse's parser with jourdain's exit status of a usage error (2) and message."""

    def error(self, message: str) -> NoReturn:
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"{self.prog}: usage error: {shorten_words(message)}\n")


def subcommand(subs: Any, name: str, help: str, example: str, func: Callable[..., int]) -> Any:
    p = subs.add_parser(name, help=help, description=help,
                        epilog=f"example:\n  {example}",
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model", metavar="MODEL", help="model file (TOML, see docs/model-format.md)")
    p.set_defaults(func=func)
    return p


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="jourdain",
        description="Multibody dynamics by the Newton–Euler projection method (Schiehlen): "
                    "equations of motion, reactions, linearization, simulation and reports "
                    "from a TOML model file.",
        epilog="example:\n  jourdain run examples/double_pendulum.toml --out report/",
        formatter_class=argparse.RawDescriptionHelpFormatter)

    parser.add_argument("--version", action="version", version=f"jourdain {__version__}")
    subs = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)

    p = subcommand(subs, "check", "validate a model file and summarize it (bodies, joints, degrees of "
             "freedom, constraints)", "jourdain check examples/double_pendulum.toml", cmd_check)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")

    p = subcommand(subs, "eom", "print M̄, J̄, q̄^c, q̄^e and M, k, q",
             "jourdain eom examples/double_pendulum.toml --format latex", cmd_eom)
    p.add_argument("--format", choices=("text", "latex", "json"), default="text",
                   help="text (default), latex, or json (expressions with shared temporaries)")
    p.add_argument("--max-ops", type=operations, default=600, metavar="N",
                   help="summarize matrices needing more than N operations (text, latex)")

    state_help = ('state as "name=value, ..." with coordinates, rates <name>_d, inputs and t '
                  "(unset values: the model's [simulation] y0/yd0, else 0)")
    set_help = "override a parameter: --set m1=2.0 (repeatable, or comma-separated)"

    p = subcommand(subs, "eval", "numeric values of every matrix and vector of the method at one "
             "state (a stable JSON contract with --json)",
             'jourdain eval examples/double_pendulum.toml --at "phi1=0.3, phi1_d=1.0, t=0" '
             "--json", cmd_eval)
    p.add_argument("--at", metavar="STATE", help=state_help)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--json", action="store_true", help=f"print JSON ({EVAL_FORMAT})")

    p = subcommand(subs, "reactions", "generalized reaction forces g at one state (N̂·g = k̂ − q̂)",
             'jourdain reactions examples/double_pendulum.toml --at "phi1=0.3"', cmd_reactions)
    p.add_argument("--at", metavar="STATE", help=state_help)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--json", action="store_true", help="print JSON")

    p = subcommand(subs, "linearize", "linearize about a nominal motion: M̃, P, Q, h; D, G, K, N; "
             "eigenvalues and stability",
             "jourdain linearize examples/double_pendulum.toml --about hanging", cmd_linearize)
    p.add_argument("--about", metavar="NAME",
                   help="nominal motion of the model file ([nominal.NAME]; default: the first)")
    p.add_argument("--periodic", metavar="T",
                   help="Floquet analysis of a T-periodic nominal motion: monodromy matrix, "
                        "multipliers, exponents and verdict (T a number or an expression in "
                        'the parameters, "2*pi/w"; default: the period = ... of the nominal motion '
                        "in the model file, if it has one)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--json", action="store_true", help="print JSON")


    default = "(default: the model's [simulation] {}, else {})".format
    t_end_help = (f"end time, at most {sim.MAX_TIME:g} {default('t_end', sim.DEFAULT_T_END)}")
    progress_help = (f"print t and the fraction done to stderr every {PROGRESS_SECONDS:g} s "
                     "(without it: only when stderr is a terminal)")
    p = subcommand(subs, "simulate", "integrate the nonlinear equations of motion",
             "jourdain simulate examples/double_pendulum.toml --t-end 10 --out sim.csv\n  "
             'jourdain simulate examples/quarter_car.toml --method Radau --rtol 1e-9 '
             '--y0 "z_b=0.05" --input "z_r=0.02*sin(8*t)"', cmd_simulate)
    p.add_argument("--t-end", metavar="T", help=t_end_help)
    p.add_argument("--samples", metavar="N",
                   help=f"output samples, evenly spaced from t = 0 ({sim.MIN_SAMPLES} to "
                        f"{sim.MAX_SAMPLES:g}) {default('samples', sim.DEFAULT_SAMPLES)}")
    p.add_argument("--method", choices=SIM_METHODS,
                   help=f"integration method {default('method', sim.DEFAULT_METHOD)}")
    p.add_argument("--rtol", metavar="R",
                   help=f"relative tolerance, {sim.RTOL_MIN:g} <= R < 1 "
                        f"{default('rtol', f'{sim.DEFAULT_RTOL:g}')}")
    p.add_argument("--atol", metavar="A",
                   help=f"absolute tolerance, 0 < A <= {sim.ATOL_MAX:g} "
                        f"{default('atol', f'{sim.DEFAULT_ATOL:g}')}")
    p.add_argument("--y0", action="append", default=[], metavar="STATE",
                   help='initial coordinates: --y0 "phi1=0.3, phi2=0" (the others: the model\'s '
                        "[simulation] y0, else 0)")
    p.add_argument("--yd0", action="append", default=[], metavar="RATES",
                   help='initial rates: --yd0 "phi1=1.0" (or phi1_d=1.0; the others: the '
                        "model's [simulation] yd0, else 0)")
    p.add_argument("--input", action="append", default=[], metavar="NAME=LAW",
                   help='input law: --input "F=2.0" or "F=2*sin(3*t)", an expression in t and '
                        "the parameters (the others: the model's [simulation] inputs, else 0)")
    p.add_argument("--out", metavar="FILE",
                   help="write the results as the run goes (.csv, or .h5 for HDF5)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    p.add_argument("--progress", action="store_true", help=progress_help)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)

    p = subcommand(subs, "run", "everything for a model, written as a self-contained HTML report "
             "plus data files", "jourdain run examples/double_pendulum.toml --out report/",
             cmd_run)
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder (not the model file's own)")
    p.add_argument("--force", action="store_true",
                   help="overwrite the files of an earlier report in --out")
    p.add_argument("--t-end", metavar="T", help="simulation " + t_end_help)
    p.add_argument("--progress", action="store_true", help=progress_help)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--max-ops", type=operations, default=600, metavar="N",
                   help="summarize matrices needing more than N operations")
    p.add_argument("--study", metavar="STUDY",  # a parameter study's section (H3)
                   help="also run this study file on the model (docs/studies.md) and show its "
                        "stability map, Campbell diagram or histograms in the report")

    p = subcommand(subs, "fmu", "export an FMI 2.0 FMU (model exchange and co-simulation, C sources "
             "and a binary for this machine; docs/fmu.md)",
             "jourdain fmu examples/double_pendulum.toml --out double_pendulum.fmu "
             "--reaction hinge1.F_x,hinge1.F_y", cmd_fmu)
    p.add_argument("--out", required=True, metavar="FILE", help="the .fmu file to write")
    p.add_argument("--force", action="store_true", help="replace an existing --out file")
    p.add_argument("--reaction", action="append", default=[], metavar="NAME",
                   help='reaction components as outputs: --reaction hinge1.F_x (repeatable, or '
                        'comma-separated; "all" for every one)')
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter's start value in the FMU: --set m1=2.0 (repeatable)")
    p.add_argument("--identifier", metavar="NAME",
                   help="FMI modelIdentifier, the binary's name (default: from the model's name)")
    p.add_argument("--sources-only", action="store_true",
                   help="no binary: the FMU holds the C sources only")


    add_study_parser(subs, Parser)
    return parser


def operations(text: str) -> int:
    """``--max-ops``: a whole number of operations, 0 or more."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if n < 0:
        raise argparse.ArgumentTypeError(f"expected 0 or more operations, got {n}")
    return n

