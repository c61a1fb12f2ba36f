"""Export a model as an FMI 2.0 FMU for model exchange and co-simulation (``docs/fmu.md``).

:func:`export_fmu` writes one ``.fmu`` (a zip archive) holding

- ``modelDescription.xml``: the coordinates ``y`` and rates ``ẏ`` as continuous states and
  outputs (their start values are the initial state), ``der(y)`` and ``der(y_d)`` (= ÿ) as
  their derivatives, the parameters as tunable parameters and the inputs as inputs (with the
  model's units), the chosen reaction components ``<joint>.F_x`` ... as outputs;
- ``sources/``: the generated C of the model (jourdain's recursion: ``jd_local.c``,
  ``jd_engine.c``), the FMI 2.0 functions (``fmi2.c``), ``model.h``, the Runge–Kutta tables
  and the FMI 2.0 headers, with ``buildDescription.xml``;
- ``binaries/linux64/<modelIdentifier>.so`` (``darwin64/*.dylib`` on macOS): those sources
  compiled with the machine's C compiler. No Python is needed where the FMU runs.

Model exchange gives ``ẋ = [ẏ; ÿ]`` with ``ÿ = M⁻¹(q − k)`` (the articulated-body recursion
where every coordinate belongs to one joint, else LDLᵀ of M); co-simulation integrates that with
the Dormand–Prince 5(4) pair under error control (tolerance of ``fmi2SetupExperiment``, default
the DefaultExperiment's). The FMI 2.0 headers come from FMPy (the ``fmu`` extra:
``pip install "jourdain[fmu]"``).

A closed system (closing joints, METHOD.md §7) is exported in its independent coordinates:
the states are ``[y_i; ẏ_i]`` of the partition chosen at the (assembled) initial configuration
and fixed in the FMU; ``jd_loop.c`` (the generated Φ, Φ_z, Φ_t and convective term, the kernel
``jourdain/loops/loop_c.h`` and ``closed.c``) solves the dependent coordinates by Newton on
``Φ = 0``, the dependent rates by the velocity map and ``ÿ_i`` from ``M = J_zᵀ M_tree J_z``
with the tree's compiled ``M, k, q`` (``jd_fn`` of ``jd_engine.c``); the dependent coordinates,
their rates and the closure residuals ``Phi.<row>`` are outputs. Where ``Φ_d`` becomes singular
(its condition number passes ``cond_limit``) or Newton fails the FMU returns fmi2Error with a
logged message.
"""

from __future__ import annotations

import hashlib
import os
import re
import tempfile
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...errors import ClosedSystemError, EvaluationError, JourdainError, ModelError
from ...model.system import System
from ...numeric import parameter_vector
from ...numeric.ccode import argument_names, function_source
from ...numeric.integrator_c import tables as rk_tables
from ...numeric.recursive import recursive_units
from ...numeric.toolchain import compiler
from ...version import __version__
from .binary import (
    CLOSED_SOURCES,
    FMI_HEADERS,
    SOURCES,
    _binary,
    fmi_header_dir,
    platform_folder,
)
from .description import build_description, layout, model_description
from .sources import (
    _C_KEYWORDS,
    _array,
    _closed_header,
    _finite,
    _model_header,
    _reaction_names,
    _state,
    _tables,
    model_identifier_of,
)

__all__ = ["FmuExport", "FMI_HEADERS", "export_fmu", "fmi_header_dir", "platform_folder"]


DEFAULT_TOLERANCE = 1e-8
_HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class FmuExport:
    """What :func:`export_fmu` wrote.

    Attributes
    ----------
    path : the ``.fmu`` file
    model_identifier : the FMI modelIdentifier (the binary's name)
    guid : the FMU's GUID (a hash of its model description and sources)
    variables : the variable names in value-reference order
    reactions : the reaction components given as outputs
    binary : the binary's path inside the FMU, or None for a sources-only FMU
    states : the number of continuous states (2f; a closed system's f independent coordinates)
    independent : a closed system's independent coordinates (the states), else ()
    """

    path: Path
    model_identifier: str
    guid: str
    variables: tuple[str, ...]
    reactions: tuple[str, ...]
    binary: str | None
    states: int = 0
    independent: tuple[str, ...] = ()


def _model_of(model: Any) -> tuple[System, Any]:
    if isinstance(model, System):
        return model, None
    system = getattr(model, "system", None)
    if isinstance(system, System):
        return system, model
    raise ModelError(f"export_fmu: expected a jourdain.System or a model file (load_model), got "
                     f"{type(model).__name__}")


def export_fmu(model: Any, path: str | os.PathLike[str], *,
               reactions: Sequence[str] | str | None = None,
               y0: Mapping[str, float] | Sequence[float] | None = None,
               yd0: Mapping[str, float] | Sequence[float] | None = None,
               parameters: Mapping[str, float] | None = None,
               model_identifier: str | None = None, stop_time: float | None = None,
               tolerance: float = DEFAULT_TOLERANCE, binary: bool = True,
               cond_limit: float = 1e6) -> FmuExport:
    """Write ``model`` as an FMI 2.0 FMU (model exchange and co-simulation) to ``path``.

    Parameters
    ----------
    model : jourdain.System, or a model file from :func:`jourdain.io.load_model` (its
        ``[simulation]`` y0, yd0 and t_end, its descriptions and units are used)
    path : the ``.fmu`` file to write (replaced if it exists)
    reactions : reaction components to give as outputs, by name (``["hinge1.F_x", ...]``),
        ``"all"``, or None (none)
    y0, yd0 : start values of the coordinates and rates (by name or in order; default: the
        model file's, else 0); an importer may set others before initialization
    parameters : start values of parameters that differ from the model's (by name)
    model_identifier : the FMI modelIdentifier (default: from the model's name)
    stop_time, tolerance : the DefaultExperiment (stop time default: the model file's t_end,
        else 5); ``tolerance`` is also co-simulation's relative tolerance when the importer
        gives none
    binary : compile the binary for this machine (False: sources only)
    cond_limit : a closed system's limit on the condition number of Φ_d (the partition is
        fixed in the FMU; past it the FMU returns fmi2Error), as System.simulate's

    Raises
    ------
    ModelError : unknown reaction names, reactions that cannot be formed, C that cannot be
        generated for an expression of the model
    CompilerError : no C compiler, or the sources did not compile
    MissingDependency : FMPy (the FMI headers) not installed
    """

    system, mf = _model_of(model)
    general = bool(getattr(system, "is_general", False))  # velocity constraints
    closed = bool(getattr(system, "closing", ())) or general
    if closed and reactions is not None and (isinstance(reactions, str) or list(reactions)):
        raise ClosedSystemError(system, "the FMU of a closed system gives no reaction "
                                "outputs yet (export it without reactions)")
    if not cond_limit > 1:
        raise EvaluationError(f"cond_limit must be > 1, got {cond_limit!r}")
    if system.f == 0:
        raise ModelError(f"{system.name!r} has no coordinates: an FMU needs continuous states")
    if not (0.0 < float(tolerance) < 1.0):
        raise EvaluationError(f"tolerance must lie in (0, 1), got {tolerance!r}")
    sim = getattr(mf, "simulation", None)
    if y0 is None and sim is not None:
        y0 = list(sim.y0)
    if yd0 is None and sim is not None:
        yd0 = list(sim.yd0)
    if stop_time is None:
        stop_time = float(sim.t_end) if sim is not None else 5.0
    stop_time = _finite(stop_time, "stop_time")
    if stop_time <= 0:
        raise EvaluationError(f"stop_time must be > 0, got {stop_time}")
    y0v = _state(system, y0, "y0", "")
    yd0v = _state(system, yd0, "yd0", "_d")
    # the start values, checked as every evaluation checks them (known names, finite numbers,
    # mass data a rigid body can have)
    tree = system.tree if closed else system
    pvals = dict(zip(tree.parameter_values,
                     (float(x) for x in parameter_vector(tree, parameters)), strict=True))
    ident = model_identifier or model_identifier_of(system.name)
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,63}", ident) or ident in _C_KEYWORDS:
        raise ModelError(f"model_identifier {ident!r} must be a C identifier (letters, digits, "
                         "_; at most 64 characters)")
    headers = fmi_header_dir()
    folder, suffix = platform_folder() if binary else ("", "")
    if binary:
        compiler()  # the missing compiler is named before any work

    joints, chosen = ([], []) if closed else _reaction_names(system, reactions)
    units = dict(system.units)
    descriptions = dict(getattr(mf, "descriptions", ()) or ())
    closed_h, loop_src, independent = "", "", ()
    coords = system.coordinate_names
    extra_out: list[tuple[str, str | None, str]] = []
    if closed:
        parts = _general_parts if general else _closed_parts
        closed_h, loop_src, coords, y0v, yd0v, extra_out = parts(
            system, pvals, y0v, yd0v, float(cond_limit), units, descriptions)
        independent = tuple(coords)
    lay = layout(coords, pvals, system.input_names, chosen, y0v, yd0v, units, descriptions,
                 extra_out)
    names = [v.name for v in lay.variables]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ModelError(f"the FMU's variable names {dup} are not unique (a parameter or input "
                         "named like a coordinate's rate, der(...) or time); rename it")

    # the C of the model: the recursion, and the constrained directions of the chosen joints
    tables, dir_exprs = _tables(joints, chosen, [b.name for b in system.bodies])
    try:
        extra = ""
        if dir_exprs:
            cnames = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                                    system.inputs)
            extra = function_source("jd_dirs", dir_exprs, cnames)
        local, engine = recursive_units(tree, full=False, extra_source=extra)
    except JourdainError as exc:  # e.g. a function C has no counterpart for
        raise ModelError(f"{system.name!r} cannot be exported as an FMU: {exc}") from None
    rk = rk_tables()
    glue = (_HERE / "fmi2.c").read_text()
    order = CLOSED_SOURCES if closed else SOURCES

    def describe(guid: str) -> str:
        return model_description(
            lay, model_name=system.name, model_identifier=ident, guid=guid,
            description=" ".join(str(getattr(mf, "description", "") or "").split()),
            version=__version__, sources=order, start_time=0.0, stop_time=stop_time,
            tolerance=float(tolerance), step_size=None)

    # the GUID: a hash of everything that makes the FMU (reproducible, never random)
    h = hashlib.sha256()
    for part in (describe("{}"), local, engine, glue, rk, tables, closed_h, loop_src):
        h.update(part.encode())
        h.update(b"\0")
    d = h.hexdigest()
    guid = f"{{{d[:8]}-{d[8:12]}-{d[12:16]}-{d[16:20]}-{d[20:32]}}}"
    files: dict[str, bytes] = {
        "modelDescription.xml": describe(guid).encode(),
        "sources/jd_local.c": local.encode(),
        "sources/jd_engine.c": engine.encode(),
        "sources/fmi2.c": glue.encode(),
        "sources/model.h": _model_header(lay, guid, float(tolerance), len(tree.bodies), tables,
                                         closed_h).encode(),
        "sources/rk_tables.h": rk.encode(),
        "sources/buildDescription.xml": build_description(ident, order).encode(),
    }
    if closed:
        files["sources/jd_loop.c"] = loop_src.encode()
    for hname in FMI_HEADERS:
        files[f"sources/{hname}"] = (headers / hname).read_bytes()
    binary_name = None
    if binary:
        binary_name = f"binaries/{folder}/{ident}{suffix}"
        files[binary_name] = _binary({k: v for k, v in files.items() if k.startswith("sources/")},
                                     f"{ident}{suffix}", order)
    out = Path(path)
    _write_zip(out, files)
    return FmuExport(out, ident, guid, tuple(names), tuple(chosen), binary_name,
                     2 * len(coords), independent)


def _closed_parts(system: System, pvals: Mapping[str, float], y0v: list[float],
                  yd0v: list[float], cond_limit: float, units: Mapping[str, str],
                  descriptions: Mapping[str, str]) -> tuple:
    """A closed system's model.h part, the source of jd_loop.c, the independent coordinates
    with their (assembled) start values and the further outputs: the initial configuration
    assembled as System.simulate assembles it (the independent coordinates held), and the
    partition chosen there, which the FMU keeps."""
    from ...loops import LoopEvaluator, constraints
    from ...loops.compiled import loop_source

    tree = system.tree
    try:
        ev = LoopEvaluator(system, y0v, 0.0, dict(pvals), None)
        asm = ev.assemble(y0v, yd0v, 0.0)
        con = constraints(system)
        src = loop_source(system)
    except JourdainError as exc:
        raise ModelError(f"{system.name!r} cannot be exported as an FMU: {exc}") from None
    loop_src = (src + "\n/* ---- the FMU's adapter (jourdain/io/fmu/closed.c) ---- */\n"
                + (_HERE / "closed.c").read_text())
    part = ev.part
    all_names = tree.coordinate_names
    ind, dep = list(part.independent), list(part.dependent)
    head = _closed_header(tree.f, len(con.labels), ind, dep, part.rows,
                          [float(v) for v in asm.z], ev.newton_tol, ev.max_newton, cond_limit)
    coords = [all_names[i] for i in ind]
    out = _dependent_outputs(all_names, dep, units, descriptions, "the closure")
    for label in con.labels:
        out.append((f"Phi.{label}", None, f"closure residual: the constraint row {label}"))
    return (head, loop_src, coords, [float(asm.z[i]) for i in ind],
            [float(asm.zd[i]) for i in ind], out)


def _dependent_outputs(names: Sequence[str], dep: Sequence[int], units: Mapping[str, str],
                       descriptions: Mapping[str, str], source: str
                       ) -> list[tuple[str, str | None, str]]:
    """The FMU's outputs of the dependent coordinates and their rates (solved from
    ``source``), as (name, unit, description)."""
    out: list[tuple[str, str | None, str]] = []
    for i in dep:
        c = names[i]
        text = descriptions.get(c, f"coordinate {c}")
        out.append((c, units.get(c), f"{text} (dependent: solved from {source})"))
    for i in dep:
        c = names[i]
        u = units.get(c)
        out.append((f"{c}_d", f"{u}/s" if u else None, f"rate of {c} (dependent)"))
    return out


def _general_parts(system: System, pvals: Mapping[str, float], y0v: list[float],
                   yd0v: list[float], cond_limit: float, units: Mapping[str, str],
                   descriptions: Mapping[str, str]) -> tuple:
    """A general system's (velocity constraints) model.h part, the source of jd_loop.c
    (:func:`jourdain.loops.general_kernel.general_source` and ``general.c``), the independent
    coordinates with their start values and the further outputs (dependent coordinates and
    rates, every row's residual): the partition chosen at the initial state, which the FMU
    keeps; speeds that are rates of independent coordinates only."""
    from ...loops.general import GeneralEvaluator
    from ...loops.general_choice import general_constraints
    from ...loops.general_kernel import general_source, supported

    tree = system.tree
    try:
        ev = GeneralEvaluator(system, y0v, 0.0, dict(pvals))
        if not supported(ev):
            raise ClosedSystemError(system, "the FMU of a system with velocity constraints "
                                    "needs speeds that are rates of independent coordinates "
                                    "(speeds=[names])")
        s0 = ev.accelerations(ev.initial(y0v, yd0v, 0.0), 0.0)
        con = general_constraints(system)
        src = general_source(system)
    except ClosedSystemError:
        raise
    except JourdainError as exc:
        raise ModelError(f"{system.name!r} cannot be exported as an FMU: {exc}") from None
    loop_src = (src + "\n/* ---- the FMU's adapter (jourdain/io/fmu/general.c) ---- */\n"
                + (_HERE / "general.c").read_text())
    ch = ev.choice
    all_names = tree.coordinate_names
    ind, dep = list(ch.independent), list(ch.dependent)
    head = (_closed_header(tree.f, con.r, ind, dep, ch.rows_h, [float(v) for v in s0["y"]],
                           ev.newton_tol, ev.max_newton, 1e300)
            + f"#define JD_NPOS {con.Phi.shape[0]}\n#define JD_NSPD {len(ch.speeds)}\n"
            + _array("long", "jd_rows_v", ch.rows_v)
            + _array("long", "jd_spd", ch.speed_coordinates or ()))
    coords = [all_names[i] for i in ind]
    out = _dependent_outputs(all_names, dep, units, descriptions,
                             "the contacts' holonomic rows")
    for k, label in enumerate(con.labels):
        what = "Φ" if k < con.r_h else "A·ẏ + a"
        out.append((f"Phi.{label}", None, f"residual of the row {label} ({what})"))
    return (head, loop_src, coords, [float(s0["y"][i]) for i in ind],
            [float(s0["yd"][i]) for i in ind], out)


def _write_zip(out: Path, files: Mapping[str, bytes]) -> None:
    """The FMU archive, written under a temporary name and renamed (never half-written);
    fixed timestamps, so that the same model gives the same bytes."""
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".fmu.tmp", dir=out.parent)
    os.close(fd)
    try:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
            for name, data in files.items():
                info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = (0o755 if name.startswith("binaries/") else 0o644) << 16
                zf.writestr(info, data)
        os.replace(tmp, out)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
