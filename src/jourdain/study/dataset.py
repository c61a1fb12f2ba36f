"""Study results and simulation results as labelled arrays (``xarray.Dataset``), and NetCDF.

A study's dataset has one dimension per grid axis (named after the varied quantity, with its
values as coordinate) or one ``case`` dimension (list and random designs; the varied values are
coordinates along it), plus ``coordinate`` (and ``coordinate_j``: the columns of M), ``state``
(coordinates then rates), ``mode``, ``time`` and ``wrench_component`` where the outputs have
them. Variables carry ``units`` and ``long_name`` attributes; the dataset carries the model's
SHA-256 (``model_hash``), the study file and the jourdain version. The ``verdict`` follows the
CF conventions (``flag_values``, ``flag_meanings``; −1: the case failed). Complex eigenvalues
are stored as ``eigenvalue_real`` and ``eigenvalue_imag`` (NetCDF has no complex type).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from ..extras import missing, require
from ..io.interrupted import deferred_ctrl_c
from ..simulation.labelled import results_dataset
from .compute import VERDICTS, WRENCH_COMPONENTS, Context, output_layout

__all__ = ["open_study", "results_dataset", "to_dataset", "write_netcdf"]


def xarray() -> Any:
    """The xarray module, or a clear error naming the extra that installs it."""
    return require("xarray", "A parameter study's output (xarray)", "study")


@lru_cache(maxsize=1)
def _version() -> str:
    """The installed jourdain's version (from its distribution: this module sits below the
    package's ``__init__``, which holds the same number); read once per process (the
    distribution's metadata: 1.3 ms, 2 % of a 10 000-case stability map)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("jourdain")
    except PackageNotFoundError:  # run from a source tree that is not installed
        return "unknown"


def _units(ctx: Context) -> dict[str, str]:
    from ..units import model_units, per_time

    units = model_units(ctx.system)
    for n in ctx.system.coordinate_names:
        if n in units:
            units[f"{n}_d"] = per_time(units[n], 1)
    return units


def to_dataset(ctx: Context, blocks: Sequence[dict[str, Any]]) -> Any:
    """The dataset of a study from its blocks (in case order)."""
    xr = xarray()
    spec, system = ctx.spec, ctx.system
    layout = output_layout(ctx)
    units = _units(ctx)
    coords_names = system.coordinate_names
    grid = spec.design == "grid"
    lead = spec.names if grid and spec.varied else ("case",)
    shape = spec.shape if grid and spec.varied else (spec.n_cases,)
    data_vars: dict[str, Any] = {}
    for name, (dims, _, _) in layout.items():
        arr = np.concatenate([b["outputs"][name] for b in blocks], axis=0)
        arr = arr.reshape(*shape, *arr.shape[1:])
        data_vars[name] = xr.Variable((*lead, *dims), arr, attrs=_attrs(ctx, name, units))
    errors = np.array([e for b in blocks for e in b["errors"]], dtype=str).reshape(shape)
    data_vars["error"] = xr.Variable(lead, errors, attrs={
        "long_name": "the error of a failed case (empty where the case succeeded)"})
    coords: dict[str, Any] = {}
    if grid and spec.varied:
        for v in spec.varied:
            coords[v.name] = xr.Variable((v.name,), np.asarray(v.values, dtype=float),
                                         attrs=_varied_attrs(v, units))
    else:
        cases = ctx.cases
        coords["case"] = np.arange(spec.n_cases)
        for j, v in enumerate(spec.varied):
            coords[v.name] = xr.Variable(("case",), cases[:, j], attrs=_varied_attrs(v, units))
    used = {d for dims, _, _ in layout.values() for d in dims}
    if "coordinate" in used:
        coords["coordinate"] = list(coords_names)
    if "coordinate_j" in used:
        coords["coordinate_j"] = list(coords_names)
    if "state" in used:
        coords["state"] = [*coords_names, *(f"{n}_d" for n in coords_names)]
    if "mode" in used:
        coords["mode"] = np.arange(2 * ctx.f_linear)
    if "wrench_component" in used:
        coords["wrench_component"] = list(WRENCH_COMPONENTS)
    if "omega" in used:
        fr = spec.compute["frequency_response"]
        coords["omega"] = xr.Variable(("omega",), np.asarray(fr["omega"], dtype=float),
                                      attrs={"units": "rad/s",
                                             "long_name": "excitation angular frequency"})
        coords["excitation"] = (list(system.input_names) if fr["excitation"] == "inputs"
                                else list(coords_names))
    if "time" in used:
        s = spec.compute["simulate"]
        coords["time"] = xr.Variable(("time",), np.linspace(0.0, s["t_end"], s["samples"]),
                                     attrs={"units": "s", "long_name": "time"})
    attrs = {"title": f"jourdain study {spec.name}", "study": spec.name,
             "design": spec.design, "model": system.name, "model_file": spec.model_path,
             "model_hash": spec.model_hash, "compiled_keys": json.dumps(ctx.keys),
             "spec_hash": spec.spec_hash, "study_file": spec.source,
             "computed": json.dumps(sorted(spec.compute)),
             "jourdain_version": _version(), "n_cases": spec.n_cases,
             "n_failed": int(np.count_nonzero(errors != ""))}
    if spec.design == "random":
        attrs["seed"] = int(spec.seed or 0)
        attrs["distributions"] = json.dumps({v.name: [v.distribution, *v.arguments]
                                             for v in spec.varied})
    if "critical" in spec.compute:
        c = spec.compute["critical"]
        attrs["critical_bracket"] = json.dumps([c["lower"], c["upper"]])
    if "linearize" in spec.compute or "critical" in spec.compute:
        attrs["nominal_motion"] = (spec.compute.get("linearize")
                                   or spec.compute["critical"])["about"]
        attrs["cyclic_coordinates"] = ", ".join(ctx.cyclic)
    if ctx.closed:
        attrs["closing_joints"] = ", ".join(c.name for c in system.closing)
        attrs["independent_coordinates"] = ", ".join(ctx.independent)
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def _varied_attrs(v: Any, units: dict[str, str]) -> dict[str, str]:
    what = {"parameter": "parameter", "y0": "initial coordinate", "yd0": "initial rate"}[v.kind]
    out = {"long_name": f"{what} {v.name}", "varied": v.kind}
    if units.get(v.name):
        out["units"] = units[v.name]
    return out


def _attrs(ctx: Context, name: str, units: dict[str, str]) -> dict[str, Any]:
    if name == "verdict":
        return {"long_name": "stability verdict of the linearization",
                "flag_values": np.array([-1, 0, 1, 2], dtype=np.int8),
                "flag_meanings": "failed " + " ".join(v.replace(" ", "_") for v in VERDICTS)}
    if name in ("eigenvalue_real", "eigenvalue_imag", "max_real_part"):
        part = {"eigenvalue_real": "real part of the eigenvalues of A",
                "eigenvalue_imag": "imaginary part of the eigenvalues of A (sorted by it)",
                "max_real_part": "largest real part of the eigenvalues"}[name]
        return {"long_name": part, "units": "1/s"}
    for prefix, what in (("critical_", "critical value of"), ("max_abs_", "largest |·| of"),
                         ("max_", "largest value of"), ("series_", "")):
        if name.startswith(prefix):
            q = name[len(prefix):]
            out = {"long_name": f"{what} {q}".strip()}
            if units.get(q):
                out["units"] = units[q]
            return out
    if name.startswith("wrench_"):
        from ..units import force_unit, torque_unit

        return {"long_name": f"wrench of joint {name[7:]} on its child body, in the joint frame "
                f"(F_x..F_z in {force_unit(units)}, T_x..T_z in {torque_unit(units)})"}
    if name == "frf_magnitude":
        return {"long_name": "steady-state amplitude per unit excitation amplitude"}
    if name == "frf_phase":
        return {"long_name": "phase of the steady-state response (unwrapped over omega)",
                "units": "rad"}
    if name == "linearized_about":
        return {"long_name": "configuration linearized about (the tree's coordinates, on the "
                "constraint manifold)"}
    if name == "closure_residual":
        return {"long_name": "largest |Phi| of the closing joints' rows along the run"}
    if name == "closure_rate_residual":
        return {"long_name": "largest |dPhi/dt| of the closing joints' rows along the run"}
    if name == "final":
        return {"long_name": "state at the end of the run (coordinates, then rates)"}
    return {"long_name": {"evaluate_M": "mass matrix M", "evaluate_k": "k (M·ÿ + k = q)",
                          "evaluate_q": "q (applied generalized forces)",
                          "evaluate_ydd": "ÿ = M⁻¹(q − k)"}.get(name, name)}


def write_netcdf(ds: Any, path: str | Path) -> Path:
    """Write ``ds`` to NetCDF-4 (HDF5) at ``path`` (via a temporary file and a rename).

    Uses h5netcdf, else netCDF4; a missing one is named with the extra that installs it.
    A Ctrl-C while the file is written is raised when it is complete (KeyboardInterrupt
    after the rename): cut inside its ``File`` constructor, h5netcdf's destructor printed a
    traceback at exit, and the study's computed results would have been lost."""
    import os

    path = Path(path)
    engine = _engine()
    tmp = path.with_name(path.name + ".tmp")
    with deferred_ctrl_c(), _scheduler_for(ds):
        ds.to_netcdf(tmp, engine=engine)
        os.replace(tmp, path)
    return path


def _scheduler_for(ds: Any) -> Any:
    """Dask's synchronous scheduler while a dataset in memory is written, where Dask's
    configuration names the distributed scheduler but no client is left to serve it (two
    clients closed in the order they were made: each restores the configuration it found).
    xarray's writer asks Dask for its scheduler even for arrays in memory, and failed there
    with "no Client active". Otherwise, and for a dataset of Dask arrays, the configuration
    stays as the caller has it."""
    import contextlib

    if ds.chunks:
        return contextlib.nullcontext()
    try:
        import dask
    except ImportError:
        return contextlib.nullcontext()
    if dask.config.get("scheduler", None) not in ("dask.distributed", "distributed"):
        return contextlib.nullcontext()
    try:
        from distributed import default_client

        default_client()
    except (ImportError, ValueError):  # named, with no client
        return dask.config.set(scheduler="synchronous")
    return contextlib.nullcontext()


def open_study(path: str | Path) -> Any:
    """Open a study (or simulation) written by :func:`write_netcdf` as an ``xarray.Dataset``
    (loaded into memory, the file closed)."""
    xr = xarray()
    with xr.open_dataset(path, engine=_engine()) as ds:
        return ds.load()


def _engine() -> str:
    import importlib.util

    for engine, module in (("h5netcdf", "h5netcdf"), ("netcdf4", "netCDF4")):
        if importlib.util.find_spec(module) is not None:
            return engine
    raise missing("NetCDF output (h5netcdf or netCDF4)", "study", "h5netcdf")
