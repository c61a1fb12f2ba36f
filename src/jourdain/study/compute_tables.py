"""The ``[compute.*]`` tables of a study file: what to compute per case, checked.

``evaluate`` (outputs, reactions, t), ``linearize`` and ``critical`` (about a nominal motion;
the critical parameter and its bracket), ``frequency_response`` (frequencies, excitation) and
``simulate`` (span, samples, method, tolerances, outputs, ensemble). :class:`ComputeTables` is
the part of the study file's reader (:mod:`jourdain.study.reader`) that reads them; errors
name the file, line and key like the rest of the reader.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import JourdainError
from ..io.expressions import ExpressionError, parse_expression
from .spec import EVALUATE_OUTPUTS, StudyError

__all__ = ["COMPUTE_KEYS", "ComputeTables", "type_name"]

#: the keys of every ``[compute.*]`` table
COMPUTE_KEYS = {
    "evaluate": {"outputs", "reactions", "t"},
    "linearize": {"about"},
    "simulate": {"t_end", "samples", "method", "rtol", "atol", "series", "final", "max",
                 "max_abs", "ensemble"},
    "critical": {"parameter", "lower", "upper", "rtol", "about"},
    "frequency_response": {"about", "omega", "excitation"},
}


class ComputeTables:
    """Reads the ``[compute.*]`` tables; the reader supplies :meth:`error`, :meth:`table`,
    :meth:`number` and :meth:`count`."""

    def error(self, path: tuple[str | int, ...], message: str) -> StudyError:
        raise NotImplementedError

    def table(self, value: Any, path: tuple[str | int, ...], allowed: set[str]) -> dict:
        raise NotImplementedError

    def number(self, value: Any, path: tuple[str | int, ...],
               names: Mapping[str, float] | None = None) -> float:
        raise NotImplementedError

    def count(self, value: Any, path: tuple[str | int, ...], what: str) -> int:
        raise NotImplementedError

    def compute(self, value: Any, model: Any, defaults: Mapping[str, float]
                ) -> dict[str, dict[str, Any]]:
        system = model.system
        if value is None:
            raise self.error((), "nothing to compute: add [compute.evaluate], "
                             "[compute.linearize], [compute.frequency_response], "
                             "[compute.simulate] or [compute.critical]")
        comp = self.table(value, ("compute",), set(COMPUTE_KEYS))
        out: dict[str, dict[str, Any]] = {}
        nominal_names = [n.name for n in model.nominal]
        self._closed = bool(getattr(system, "closing", ()))
        for what, entry in comp.items():
            path = ("compute", what)
            entry = self.table(entry, path, COMPUTE_KEYS[what])
            if what == "evaluate":
                outs = entry.get("outputs", ["M", "k", "q"])
                if not isinstance(outs, list) or any(o not in EVALUATE_OUTPUTS for o in outs):
                    raise self.error((*path, "outputs"), f"expected a list of "
                                     f"{', '.join(EVALUATE_OUTPUTS)}, got {outs!r}")
                joints = [b.joint.name for b in system.bodies]
                reacts = entry.get("reactions", [])
                if not isinstance(reacts, list) or any(r not in joints for r in reacts):
                    raise self.error((*path, "reactions"), f"expected a list of joint names "
                                     f"({', '.join(joints)}), got {reacts!r}")
                t = self.number(entry.get("t", 0.0), (*path, "t"))
                out[what] = {"outputs": tuple(outs), "reactions": tuple(reacts), "t": t}
            elif what == "frequency_response":
                out[what] = self.frequency_response(entry, path, model, nominal_names, defaults)
            elif what in ("linearize", "critical"):
                d: dict[str, Any] = {"about": self.about(entry, path, nominal_names)}
                if what == "critical":
                    par = entry.get("parameter")
                    if par not in defaults:
                        raise self.error((*path, "parameter"), f"expected a parameter of the "
                                         f"model ({', '.join(defaults)}), got {par!r}")
                    for k in ("lower", "upper"):
                        if k not in entry:
                            raise self.error(path, "needs lower and upper (the bracket)")
                        v = entry[k]
                        if isinstance(v, str):
                            try:
                                parse_expression(v, names=set(defaults))
                            except ExpressionError as exc:
                                raise self.error((*path, k), f'"{v}": {exc}') from None
                            d[k] = v
                        else:
                            d[k] = self.number(v, (*path, k))
                    rtol = self.number(entry.get("rtol", 1e-12), (*path, "rtol"))
                    if not 0 < rtol < 1:
                        raise self.error((*path, "rtol"), f"expected 0 < rtol < 1, got {rtol}")
                    d.update(parameter=par, rtol=rtol)
                out[what] = d
            else:
                out[what] = self.simulate(entry, path, model)
        if not out:
            raise self.error(("compute",), "nothing to compute")
        return out

    def about(self, entry: dict, path: tuple[str | int, ...], nominal_names: list[str]) -> str:
        """The nominal motion named by ``about`` (the model's first one by default). A closed
        system (closing joints) may also be linearized about ``"equilibrium"``, the equilibrium
        nearest each case's initial configuration: the default where its model has no nominal
        motion."""
        closed = getattr(self, "_closed", False)
        default = (nominal_names[0] if nominal_names else "equilibrium" if closed else None)
        about = entry.get("about", default)
        if about not in nominal_names and not (closed and about == "equilibrium"):
            more = ' (or "equilibrium": a closed system\'s nearest equilibrium)' if closed else ""
            raise self.error((*path, "about"), f"no nominal motion {about!r} in the model; it "
                             f"has: {', '.join(nominal_names) or '(none)'}{more}")
        return about

    def frequency_response(self, entry: dict, path: tuple[str | int, ...], model: Any,
                           nominal_names: list[str], defaults: Mapping[str, float]
                           ) -> dict[str, Any]:
        """``about`` (a nominal motion), ``omega`` (a list of angular frequencies in rad/s, or
        ``{start, stop, num}``, evenly spaced, or with ``log = true`` logarithmically) and
        ``excitation`` (``"inputs"``: the model's inputs through B; ``"h"``: a unit
        generalized force on each coordinate)."""
        system = model.system
        about = self.about(entry, path, nominal_names)
        w = entry.get("omega")
        if isinstance(w, list) and w:
            omega = tuple(self.number(v, (*path, "omega", i), defaults) for i, v in enumerate(w))
        elif isinstance(w, dict):
            rng = self.table(w, (*path, "omega"), {"start", "stop", "num", "log"})
            if not {"start", "stop", "num"} <= set(rng):
                raise self.error((*path, "omega"), "needs start, stop and num")
            num = self.count(rng["num"], (*path, "omega", "num"), "num")
            lo = self.number(rng["start"], (*path, "omega", "start"), defaults)
            hi = self.number(rng["stop"], (*path, "omega", "stop"), defaults)
            if rng.get("log", False) is True:
                if not 0 < lo < hi:
                    raise self.error((*path, "omega"), "a logarithmic range needs 0 < start "
                                     f"< stop, got {lo} and {hi}")
                omega = tuple(float(x) for x in np.geomspace(lo, hi, num))
            else:
                omega = tuple(float(x) for x in np.linspace(lo, hi, num))
        else:
            raise self.error((*path, "omega"), "expected a list of frequencies in rad/s or "
                             "{start, stop, num}")
        if not all(np.isfinite(v) and v >= 0 for v in omega):
            raise self.error((*path, "omega"), "frequencies must be finite and non-negative")
        exc = entry.get("excitation", "inputs" if system.inputs else "h")
        if exc not in ("inputs", "h"):
            raise self.error((*path, "excitation"), f'expected "inputs" or "h", got {exc!r}')
        if exc == "inputs" and not system.inputs:
            raise self.error((*path, "excitation"), 'the model has no inputs: use "h" (a unit '
                             "generalized force on each coordinate)")
        return {"about": about, "omega": omega, "excitation": exc}

    def simulate(self, entry: dict, path: tuple[str | int, ...], model: Any) -> dict[str, Any]:
        from ..simulation.simulate import MAX_SAMPLES, check_atol, check_rtol, check_t_end

        system = model.system
        settings = model.simulation
        d: dict[str, Any] = {}
        try:
            d["t_end"] = check_t_end(self.number(entry.get("t_end", settings.t_end),
                                                 (*path, "t_end")), "t_end")
            d["rtol"] = check_rtol(self.number(entry.get("rtol", settings.rtol),
                                               (*path, "rtol")), "rtol")
            d["atol"] = check_atol(self.number(entry.get("atol", settings.atol),
                                               (*path, "atol")), 1, "atol")[0]
        except JourdainError as exc:
            raise self.error(path, str(exc)) from None
        samples = self.count(entry.get("samples", settings.samples), (*path, "samples"),
                             "samples")
        if samples < 2 or samples > MAX_SAMPLES:
            raise self.error((*path, "samples"), f"expected 2 to {MAX_SAMPLES}")
        d["samples"] = samples
        method = entry.get("method", settings.method)
        from ..io.capabilities import SIM_METHODS

        if method not in SIM_METHODS:
            raise self.error((*path, "method"), f"expected one of {', '.join(SIM_METHODS)}")
        d["method"] = method
        names = [*system.coordinate_names, *(f"{n}_d" for n in system.coordinate_names)]
        for key in ("series", "max", "max_abs"):
            vals = entry.get(key, [])
            if not isinstance(vals, list) or any(v not in names for v in vals):
                raise self.error((*path, key), f"expected a list of coordinates or rates "
                                 f"({', '.join(names)}), got {vals!r}")
            d[key] = tuple(vals)
        final = entry.get("final", True)
        if not isinstance(final, bool):
            raise self.error((*path, "final"), "expected true or false")
        d["final"] = final
        ensemble = entry.get("ensemble", True)
        if not isinstance(ensemble, bool):
            raise self.error((*path, "ensemble"), "expected true (the runs of a block advanced "
                             "together in C, the default) or false (one run per case)")
        d["ensemble"] = ensemble
        return d


def type_name(v: object) -> str:
    return {bool: "a boolean", int: "an integer", float: "a number", str: "a string",
            list: "a list", dict: "a table"}.get(type(v), type(v).__name__)
