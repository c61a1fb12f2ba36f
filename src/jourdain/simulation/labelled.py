"""A simulation's :class:`~jourdain.simulation.results.Results` as labelled arrays (an
``xarray.Dataset``: :func:`results_dataset`, behind ``Results.to_xarray()``).

Here, on the simulation's floor, rather than with the studies (:mod:`jourdain.study.dataset`
writes the studies' datasets and re-exports this function): the results must not import the
layer above them. Needs xarray (``pip install 'jourdain[study]'``).
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from ..errors import JourdainError
from ..extras import require

__all__ = ["results_dataset"]


def _xarray() -> Any:
    return require("xarray", "Labelled output (xarray)", "study")


def results_dataset(results: Any) -> Any:
    """A simulation's :class:`jourdain.Results` as an ``xarray.Dataset``: ``y``, ``yd``,
    ``ydd`` over (time, coordinate), ``u`` over (time, input), the energies where the model
    gives them; units as attributes; ``model_hash``: the content key of the compiled equations
    of motion (a SHA-256 of their generated C source)."""
    xr = _xarray()
    from ..units import per_time

    units = dict(results.units)
    coords = list(results.coordinate_names)
    data: dict[str, Any] = {}
    for name, arr, order in (("y", results.y, 0), ("yd", results.yd, 1),
                             ("ydd", results.ydd, 2)):
        if arr is None:
            continue
        cu = [per_time(units.get(c, ""), order) if units.get(c) else "" for c in coords]
        va = {"long_name": {"y": "coordinates", "yd": "rates", "ydd": "accelerations"}[name]}
        if len(set(cu)) == 1 and cu[0]:
            va["units"] = cu[0]
        else:
            va["coordinate_units"] = json.dumps(cu)
        data[name] = xr.Variable(("time", "coordinate"), np.asarray(arr, dtype=float), va)
    if results.u is not None and len(results.input_names):
        data["u"] = xr.Variable(("time", "input"), np.asarray(results.u, dtype=float),
                                {"long_name": "inputs"})
    attrs: dict[str, Any] = {"title": f"jourdain simulation {results.name}",
                             "model": results.name, "method": str(results.method),
                             "rtol": float(results.rtol), "status": str(results.status),
                             "parameters": json.dumps(dict(results.parameters or {}))}
    if results.system is not None:
        from ..numeric import mkq_function
        from ..units import energy_unit

        attrs["model_hash"] = mkq_function(results.system).key
        try:
            for n in ("kinetic_energy", "potential_energy", "total_energy"):
                data[n] = xr.Variable(("time",), np.asarray(getattr(results, n), dtype=float),
                                      {"units": energy_unit(units),
                                       "long_name": n.replace("_", " ")})
        except (JourdainError, ArithmeticError, ValueError):  # a model without energies
            pass
    c = {"time": xr.Variable(("time",), np.asarray(results.t, dtype=float), {"units": "s"}),
         "coordinate": coords}
    if results.u is not None and len(results.input_names):
        c["input"] = list(results.input_names)
    return xr.Dataset(data, coords=c, attrs=attrs)
