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
"""

from __future__ import annotations

import difflib
import hashlib
import importlib.util
import math
import os
import platform
import re
import sys
import tempfile
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ...errors import EvaluationError, JourdainError, ModelError
from ...numeric import parameter_vector
from ...numeric.ccode import argument_names, function_source
from ...numeric.integrator_c import tables as rk_tables
from ...numeric.recursive import recursive_units
from ...numeric.toolchain import (
    CompilerError,
    compile_shared,
    compiler,
    content_key,
    library_dir,
    not_private,
)
from .description import Layout, build_description, layout, model_description

if TYPE_CHECKING:
    from ...model.system import System

__all__ = ["FmuExport", "FMI_HEADERS", "export_fmu", "fmi_header_dir", "platform_folder"]

#: the FMI 2.0 headers copied into ``sources/`` (BSD-licensed, Modelica Association)
FMI_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
#: the compiled sources, in the order of buildDescription.xml
SOURCES = ("jd_local.c", "jd_engine.c", "fmi2.c")
#: flags of the FMU's binary: only the fmi2 functions are exported (FMI2_Export)
CFLAGS = ("-O2", "-fPIC", "-std=c99", "-fno-math-errno", "-fvisibility=hidden")
DEFAULT_TOLERANCE = 1e-8
_HERE = Path(__file__).resolve().parent
_C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if "
    "inline int long register restrict return short signed sizeof static struct switch typedef "
    "union unsigned void volatile while".split())


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
    """

    path: Path
    model_identifier: str
    guid: str
    variables: tuple[str, ...]
    reactions: tuple[str, ...]
    binary: str | None


def fmi_header_dir() -> Path:
    """The folder of the FMI 2.0 headers that FMPy ships (``fmpy/c-code``)."""
    from ...analysis.python_control import MissingDependency

    spec = importlib.util.find_spec("fmpy")
    if spec is None or not spec.submodule_search_locations:
        raise MissingDependency(
            "exporting an FMU needs the FMI 2.0 headers that FMPy ships, an optional dependency "
            'of jourdain: pip install "jourdain[fmu]" (or pip install fmpy)')
    for loc in spec.submodule_search_locations:
        d = Path(loc) / "c-code"
        if all((d / h).is_file() for h in FMI_HEADERS):
            return d
    raise MissingDependency(f"the installed FMPy has no FMI 2.0 headers ({', '.join(FMI_HEADERS)}"
                            ' in fmpy/c-code): pip install --upgrade "jourdain[fmu]"')


def platform_folder() -> tuple[str, str]:
    """FMI 2.0's ``binaries/`` folder and the library suffix of this machine."""
    machine = platform.machine().lower()
    bits64 = sys.maxsize > 2**32
    if sys.platform.startswith("linux") and bits64 and machine in ("x86_64", "amd64"):
        return "linux64", ".so"
    if sys.platform == "darwin" and bits64:
        return "darwin64", ".dylib"
    raise CompilerError(f"no FMI 2.0 binary folder for this platform ({sys.platform}, {machine}):"
                        " FMUs are compiled here for Linux x86_64 and macOS; export with "
                        "binary=False (jourdain fmu --sources-only) for an FMU of sources only")


def model_identifier_of(name: str) -> str:
    """A C identifier from a model's name (``"double pendulum"`` -> ``double_pendulum``)."""
    ident = re.sub(r"[^A-Za-z0-9_]+", "_", name).strip("_") or "model"
    if ident[0].isdigit() or ident in _C_KEYWORDS or ident.startswith("fmi2"):
        ident = "jd_" + ident
    return ident[:64]


def _state(system: System, values: Any, what: str, suffix: str) -> list[float]:
    """Initial coordinates or rates by name (a mapping) or in order (a sequence)."""
    f, names = system.f, system.coordinate_names
    if values is None:
        return [0.0] * f
    if isinstance(values, Mapping):
        out = [0.0] * f
        for k, v in values.items():
            key = str(k)
            if suffix and key.endswith(suffix) and key[:-len(suffix)] in names:
                key = key[:-len(suffix)]
            if key not in names:
                raise EvaluationError(f"{what}: {k!r} is not a coordinate; coordinates are "
                                      f"{', '.join(names)}")
            out[names.index(key)] = _finite(v, f"{what} {k}")
        return out
    seq = list(values)
    if len(seq) != f:
        raise EvaluationError(f"{what}: expected {f} values ({', '.join(names)}), got {len(seq)}")
    return [_finite(v, f"{what}[{i}]") for i, v in enumerate(seq)]


def _finite(v: Any, what: str) -> float:
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise EvaluationError(f"{what}: expected a number, got {v!r}") from None
    if not math.isfinite(x):
        raise EvaluationError(f"{what} = {v!r} is not finite")
    return x


def _reaction_names(system: System, reactions: Sequence[str] | str | None
                    ) -> tuple[list[Any], list[str]]:
    """The joints with their constrained directions, and the chosen components by name."""
    if reactions is None or (not isinstance(reactions, str) and not list(reactions)):
        return [], []
    from ...stages.reactions import check_reactions, joint_directions

    try:
        joints = list(joint_directions(system))
        check_reactions(system)
    except JourdainError as exc:
        raise ModelError(f"the reaction forces of {system.name!r} cannot be exported: {exc}"
                         ) from None
    names = [n for jr in joints for n in jr.names]
    if isinstance(reactions, str):
        if reactions != "all":
            raise ModelError(f'reactions: expected "all" or a list of names such as '
                             f'{names[:2]}, got {reactions!r}')
        return joints, names
    chosen: list[str] = []
    for r in reactions:
        if r not in names:
            close = difflib.get_close_matches(str(r), names, n=1)
            hint = f' (did you mean "{close[0]}"?)' if close else ""
            raise ModelError(f'reactions: "{r}" is not a reaction component of '
                             f"{system.name!r}{hint}; they are: {', '.join(names)}")
        if r not in chosen:
            chosen.append(r)
    return joints, chosen


def _tables(joints: list[Any], chosen: list[str], bodies: list[str]) -> tuple[str, list[Any]]:
    """model.h's tables of the reaction outputs and the direction expressions of jd_dirs."""
    if not chosen:
        return "", []
    used = [jr for jr in joints if any(n in chosen for n in jr.names)]
    body, ndir, off, exprs = [], [], [0], []
    for jr in used:
        body.append(bodies.index(jr.child))
        ndir.append(len(jr.wrenches))
        for w in jr.wrenches:
            exprs.extend(w)
        off.append(off[-1] + 6 * len(jr.wrenches))
    g_joint, g_dir = [], []
    for n in chosen:
        j = next(k for k, jr in enumerate(used) if n in jr.names)
        g_joint.append(j)
        g_dir.append(used[j].names.index(n))
    text = (f"#define JD_NJ {len(used)}\n#define JD_NE {max(off[-1], 1)}\n"
            + _array("int", "jd_rj_body", body) + _array("int", "jd_rj_ndir", ndir)
            + _array("int", "jd_rj_off", off) + _array("int", "jd_g_joint", g_joint)
            + _array("int", "jd_g_dir", g_dir)
            + "void jd_dirs(const double *y, const double *yd, double t, const double *p,\n"
              "             const double *u, double *out);\n")
    return text, exprs


def _array(ctype: str, name: str, values: Sequence[Any]) -> str:
    body = ", ".join(repr(float(v)) if ctype == "double" else str(int(v)) for v in values)
    return f"static const {ctype} {name}[{max(len(values), 1)}] = {{{body or '0'}}};\n"


def _model_header(lay: Layout, guid: str, tolerance: float, n_bodies: int, tables: str) -> str:
    vs = lay.variables
    f = lay.f
    x_start = [v.start for v in vs[1:1 + 2 * f]]
    p_start = [v.start for v in vs[1 + 4 * f:1 + 4 * f + lay.n_p]]
    u_start = [v.start for v in vs[1 + 4 * f + lay.n_p:1 + 4 * f + lay.n_p + lay.n_u]]
    return ("/* generated by jourdain; do not edit: sizes, start values and tables of the FMU */\n"
            "#ifndef JD_MODEL_H\n#define JD_MODEL_H\n"
            f'#define JD_GUID "{guid}"\n'
            f"#define JD_NY {f}\n#define JD_NP {lay.n_p}\n#define JD_NU {lay.n_u}\n"
            f"#define JD_NG {len(lay.reactions)}\n#define JD_NB {n_bodies}\n"
            f"#define JD_DEFAULT_TOLERANCE {tolerance!r}\n"
            + _array("double", "jd_x_start", x_start)
            + _array("double", "jd_p_start", p_start)
            + _array("double", "jd_u_start", u_start)
            + "int jd_dynamics(const double *y, const double *yd, double t, const double *p,\n"
              "                const double *u, double *ydd, double *wrench);\n"
            + tables + "#endif\n")


def _binary(sources: Mapping[str, bytes], name: str) -> bytes:
    """The compiled binary of the FMU's sources: from jourdain's cache of compiled code
    (:func:`jourdain.numeric.cache_dir`, keyed by the sources, the compiler and its flags) when
    it was built before, else compiled there by :func:`jourdain.numeric.toolchain.compile_shared`
    (one compiler per unit, in parallel) and kept."""
    cc = compiler()
    h = hashlib.sha256()
    for k, v in sorted(sources.items()):
        h.update(k.encode() + b"\0" + v + b"\0")
    key = "fmu-" + content_key("fmu", cc, *CFLAGS, h.hexdigest())
    cache = library_dir() / f"{key}{Path(name).suffix}"
    if not (cache.is_file() and not_private(cache) is None):
        try:
            compile_shared({k.split("/", 1)[1]: v for k, v in sources.items()}, SOURCES, cache,
                           CFLAGS)
        except CompilerError as exc:
            raise CompilerError(f"the FMU's binary: {exc}") from None
    return cache.read_bytes()


def _model_of(model: Any) -> tuple[System, Any]:
    from ...model.system import System

    if isinstance(model, System):
        return model, None
    system = getattr(model, "system", None)
    if isinstance(system, System):
        return system, model
    if type(model).__name__ == "ClosedLoopSystem":
        raise ModelError("export_fmu: a model with closing joints (kinematic loops) cannot be "
                         "exported; the FMU export covers tree-structured models only")
    raise ModelError(f"export_fmu: expected a jourdain.System or a model file (load_model), got "
                     f"{type(model).__name__}")


def export_fmu(model: Any, path: str | os.PathLike[str], *,
               reactions: Sequence[str] | str | None = None,
               y0: Mapping[str, float] | Sequence[float] | None = None,
               yd0: Mapping[str, float] | Sequence[float] | None = None,
               parameters: Mapping[str, float] | None = None,
               model_identifier: str | None = None, stop_time: float | None = None,
               tolerance: float = DEFAULT_TOLERANCE, binary: bool = True) -> FmuExport:
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

    Raises
    ------
    ModelError : unknown reaction names, reactions that cannot be formed, C that cannot be
        generated for an expression of the model
    CompilerError : no C compiler, or the sources did not compile
    MissingDependency : FMPy (the FMI headers) not installed
    """
    from ... import __version__

    system, mf = _model_of(model)
    if getattr(mf, "loops", None) is not None:
        raise ModelError(f"{system.name!r} has closing joints (kinematic loops): the FMU export "
                         "covers tree-structured models only; its FMU would leave the loops open")
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
    pvals = dict(zip(system.parameter_values,
                     (float(x) for x in parameter_vector(system, parameters)), strict=True))
    ident = model_identifier or model_identifier_of(system.name)
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,63}", ident) or ident in _C_KEYWORDS:
        raise ModelError(f"model_identifier {ident!r} must be a C identifier (letters, digits, "
                         "_; at most 64 characters)")
    headers = fmi_header_dir()
    folder, suffix = platform_folder() if binary else ("", "")
    if binary:
        compiler()  # the missing compiler is named before any work

    joints, chosen = _reaction_names(system, reactions)
    units = dict(system.units)
    descriptions = dict(getattr(mf, "descriptions", ()) or ())
    lay = layout(system.coordinate_names, pvals, system.input_names, chosen, y0v, yd0v,
                 units, descriptions)
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
        local, engine = recursive_units(system, full=False, extra_source=extra)
    except JourdainError as exc:  # e.g. a function C has no counterpart for
        raise ModelError(f"{system.name!r} cannot be exported as an FMU: {exc}") from None
    rk = rk_tables()
    glue = (_HERE / "fmi2.c").read_text()

    def describe(guid: str) -> str:
        return model_description(
            lay, model_name=system.name, model_identifier=ident, guid=guid,
            description=" ".join(str(getattr(mf, "description", "") or "").split()),
            version=__version__, sources=SOURCES, start_time=0.0, stop_time=stop_time,
            tolerance=float(tolerance), step_size=None)

    # the GUID: a hash of everything that makes the FMU (reproducible, never random)
    h = hashlib.sha256()
    for part in (describe("{}"), local, engine, glue, rk, tables):
        h.update(part.encode())
        h.update(b"\0")
    d = h.hexdigest()
    guid = f"{{{d[:8]}-{d[8:12]}-{d[12:16]}-{d[16:20]}-{d[20:32]}}}"
    files: dict[str, bytes] = {
        "modelDescription.xml": describe(guid).encode(),
        "sources/jd_local.c": local.encode(),
        "sources/jd_engine.c": engine.encode(),
        "sources/fmi2.c": glue.encode(),
        "sources/model.h": _model_header(lay, guid, float(tolerance), len(system.bodies), tables).encode(),
        "sources/rk_tables.h": rk.encode(),
        "sources/buildDescription.xml": build_description(ident, SOURCES).encode(),
    }
    for hname in FMI_HEADERS:
        files[f"sources/{hname}"] = (headers / hname).read_bytes()
    binary_name = None
    if binary:
        binary_name = f"binaries/{folder}/{ident}{suffix}"
        files[binary_name] = _binary({k: v for k, v in files.items() if k.startswith("sources/")},
                                     f"{ident}{suffix}")
    out = Path(path)
    _write_zip(out, files)
    return FmuExport(out, ident, guid, tuple(names), tuple(chosen), binary_name)


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
