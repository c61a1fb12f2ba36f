"""Building a model from a file: the order in which the sections are read (coordinates,
parameters, inputs, bodies, quantities, forces, then the system, its nominal motions and
simulation settings), and :func:`load_model` / :func:`loads_model`.
"""

from __future__ import annotations

import os
import re
import tomllib
from pathlib import Path as FsPath
from typing import Any

import symengine as se

from ...errors import JourdainError, ModelError
from ...model.bodies import Body
from ...model.expressions import magnitude_problem
from ...pipeline import System  # jourdain.System: the model with its stages (issue 16)
from ...simulation.simulate import (
    check_atol,
    check_rtol,
    check_samples,
    check_t_end,
)
from ..expressions import RESERVED_NAMES
from ..toml_positions import Path
from .document import ModelFile, NominalMotion, SimulationSettings
from .errors import ModelFileError, _too_big
from .forces import _Forces
from .schema import _TOP, MAX_FILE_BYTES


class _Loader(_Forces):
    """Reads one model file (text and file name) into a :class:`ModelFile`."""

    def load(self) -> ModelFile:
        too_big = _too_big(len(self.text), self.text)
        if too_big:
            raise ModelFileError(f"{self.file}: {too_big}", self.file, None, (), too_big)
        try:
            data = tomllib.loads(self.text)
        except RecursionError:
            raise self.nesting_error() from None
        except tomllib.TOMLDecodeError as exc:
            msg = str(exc)
            m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
            line = int(m.group(1)) if m else None
            if line is None and "(at end of document)" in msg:
                line = max(1, len(self.text.splitlines()))
            core = re.sub(r"\s*\(at (?:line \d+, column \d+|end of document)\)", "", msg)
            col = f", column {m.group(2)}" if m else ""
            loc = f"{self.file}:{line}" if line else self.file
            raise ModelFileError(f"{loc}: TOML syntax error{col}: {core}", self.file, line,
                                 (), core) from None
        except ValueError as exc:  # a number that Python will not convert (> 4300 digits)
            m = re.search(r"[0-9_]{1000,}", self.text)
            line = self.text.count("\n", 0, m.start()) + 1 if m else None
            loc = f"{self.file}:{line}" if line else self.file
            core = f"a number the TOML reader refuses: {exc}"
            raise ModelFileError(f"{loc}: {core}", self.file, line, (), core) from None
        self.table(data, (), _TOP)
        model = self.table(data.get("model", {}), ("model",),
                           {"name", "description", "view"})
        name = self.line_string(model.get("name", FsPath(self.file).stem), ("model", "name"))
        description = self.string(model.get("description", ""), ("model", "description"))
        view = None
        if "view" in model:
            view = self.string(model["view"], ("model", "view")).lower()
            if view not in ("xy", "xz", "yz", "yx", "zx", "zy", "3d"):
                raise self.fail(("model", "view"), f'expected one of xy, xz, yz or 3d, got '
                                f'"{model["view"]}"')

        self.read_coordinates(data)
        self.read_parameters(data)
        self.read_inputs(data)
        self.check_names()
        bodies = self.read_bodies(data)
        for b in bodies:  # an elastic body's coordinates, for the forces and the settings
            self.coords.extend(str(c) for c in getattr(b, "coordinates", ())
                               if not isinstance(b, Body) and str(c) not in self.coords)
        self.read_quantities(data)
        forces = self.read_forces(data)
        try:
            system = System(self.coords, bodies, forces, parameters=self.params,
                            inputs=self.inputs, units=self.units, name=name)
        except ModelFileError:
            raise
        except ModelError as exc:
            raise self.fail(self.locate(str(exc)), str(exc)) from None
        nominal = self.read_nominal(data, system)
        sim = self.read_simulation(data, system)
        if "closing_joints" in data or "loops" in data:
            # imported here, not at the top: jourdain.loops loads scipy.linalg (0.3 s), which
            # only models with closing joints need (no circle: loops imports nothing of io)
            from ...loops.modelfile import read_loops

            system = read_loops(self, data, system)
        if "contacts" in data or "speeds" in data:
            # velocity constraints (rolling contact): jourdain.loops.contact_file
            from ...loops.contact_file import read_contacts

            system = read_contacts(self, data, system)
        return ModelFile(self.file, system, description, nominal, sim,
                         tuple(self.descriptions.items()), view)


    def read_coordinates(self, data: dict) -> None:
        path: Path = ("coordinates",)
        bodies = data.get("bodies")
        elastic = isinstance(bodies, dict) and any(isinstance(b, dict) and "elastic" in b
                                                   for b in bodies.values())
        if "coordinates" not in data and elastic:  # the elastic coordinates may be all
            return
        if "coordinates" not in data:
            raise self.missing("missing table [coordinates] (the generalized coordinates)")
        coords = data["coordinates"]
        if isinstance(coords, list):
            for i, c in enumerate(coords):
                self.coords.append(self.name(c, (*path, i), "coordinate"))
            return
        tbl = self.table(coords, path, what="a table of coordinates or an array of names")
        for cname, spec in tbl.items():
            p = (*path, cname)
            self.name(cname, p, "coordinate")
            self.coords.append(cname)
            if isinstance(spec, str):  # shorthand: the unit
                self.units[cname] = self.line_string(spec, p)
                continue
            spec = self.table(spec, p, {"unit", "description"},
                              what='a table such as { unit = "rad" }')
            if "unit" in spec:
                self.units[cname] = self.line_string(spec["unit"], (*p, "unit"))
            if "description" in spec:
                self.descriptions[cname] = self.string(spec["description"], (*p, "description"))
        if not self.coords and not elastic:
            raise self.fail(path, "the model needs at least one coordinate")

    def read_parameters(self, data: dict) -> None:
        path: Path = ("parameters",)
        tbl = self.table(data.get("parameters", {}), path)
        for pname, spec in tbl.items():
            p = (*path, pname)
            self.name(pname, p, "parameter")
            if isinstance(spec, dict):
                spec = self.table(spec, p, {"value", "unit", "description"})
                value = self.number(self.require(spec, "value", p), (*p, "value"))
                if "unit" in spec:
                    self.units[pname] = self.line_string(spec["unit"], (*p, "unit"))
                if "description" in spec:
                    self.descriptions[pname] = self.string(spec["description"],
                                                           (*p, "description"))
            else:
                if isinstance(spec, str):
                    raise self.fail(p, f'a parameter value must be a number, got the string '
                                    f'"{spec}" (parameters are not expressions; write the number)')
                value = self.number(spec, p)
            why = magnitude_problem(value)
            if why:
                raise self.fail(p, why)
            self.params[pname] = value

    def read_inputs(self, data: dict) -> None:
        path: Path = ("inputs",)
        inputs = data.get("inputs", {})
        if isinstance(inputs, list):
            for i, c in enumerate(inputs):
                self.inputs.append(self.name(c, (*path, i), "input"))
            return
        tbl = self.table(inputs, path, what="a table of inputs or an array of names")
        for iname, spec in tbl.items():
            p = (*path, iname)
            self.name(iname, p, "input")
            self.inputs.append(iname)
            if isinstance(spec, str):
                self.units[iname] = self.line_string(spec, p)
                continue
            spec = self.table(spec, p, {"unit", "description"})
            if "unit" in spec:
                self.units[iname] = self.line_string(spec["unit"], (*p, "unit"))
            if "description" in spec:
                self.descriptions[iname] = self.string(spec["description"], (*p, "description"))

    def check_names(self) -> None:
        seen: dict[str, str] = {}
        groups = (("coordinates", self.coords), ("parameters", list(self.params)),
                  ("inputs", self.inputs))
        for section, names in groups:
            for n in names:
                p: Path = (section, n)
                if n in RESERVED_NAMES:
                    raise self.fail(p, f'"{n}" is a reserved name (a function, a constant, t, '
                                    "world or elongation); choose another name")
                if n in seen:
                    raise self.fail(p, f'"{n}" is already declared in [{seen[n]}]')
                seen[n] = section
        for c in self.coords:
            for suffix in ("_d", "_dd"):
                if c + suffix in seen:
                    raise self.fail((seen[c + suffix], c + suffix),
                                    f'"{c + suffix}" is the name of the rate of coordinate '
                                    f'"{c}"; choose another name')

    # --- nominal motions and simulation ---------------------------------------------------
    def read_nominal(self, data: dict, system: System) -> tuple[NominalMotion, ...]:
        path: Path = ("nominal",)
        tbl = self.table(data.get("nominal", {}), path, what="tables [nominal.<name>]")
        allowed = set(self.params) | {"t"}
        ctx = "a nominal motion (parameters and t)"
        t = se.Symbol("t")
        out = []
        for nname, spec in tbl.items():
            p = (*path, nname)
            self.name(nname, p, "nominal motion")
            spec = self.table(spec, p, {"y", "yd", "inputs", "description", "period"})

            def values(key: str, spec: dict = spec, p: Path = p) -> dict[str, se.Basic]:
                tb = self.table(spec.get(key, {}), (*p, key),
                                what="a table of coordinate = value")
                out: dict[str, se.Basic] = {}
                for c, v in tb.items():
                    if c not in self.coords:
                        raise self.fail((*p, key, c), f'"{c}" is not a declared coordinate'
                                        f"{self.suggest(c, self.coords)}")
                    out[c] = self.expr(v, (*p, key, c), allowed, ctx)
                return out

            y = values("y")
            y_full = tuple(y.get(c, se.Integer(0)) for c in self.coords)
            if "yd" in spec:
                yd = values("yd")
                yd_full = tuple(yd.get(c, se.diff(y.get(c, se.Integer(0)), t))
                                for c in self.coords)
            else:
                yd_full = tuple(se.diff(e, t) for e in y_full)
            ydd_full = tuple(se.diff(e, t) for e in yd_full)
            desc = self.string(spec.get("description", ""), (*p, "description"))
            ins = []
            for iname, v in self.table(spec.get("inputs", {}), (*p, "inputs"),
                                       what="a table of input = value").items():
                if iname not in self.inputs:
                    raise self.fail((*p, "inputs", iname), f'"{iname}" is not a declared input'
                                    f"{self.suggest(iname, self.inputs)}")
                ins.append((iname, self.expr(v, (*p, "inputs", iname), allowed, ctx)))
            period = None
            if "period" in spec:
                period = self.expr(spec["period"], (*p, "period"), set(self.params),
                                   "a period (parameters only)")
                value = float(period.subs({se.Symbol(k): v for k, v in self.params.items()}))
                if not value > 0:
                    raise self.fail((*p, "period"), f"the period must be positive, it is "
                                    f"{value:g} at the default parameter values")
            out.append(NominalMotion(nname, y_full, yd_full, ydd_full, desc, tuple(ins), period))
        return tuple(out)

    def read_simulation(self, data: dict, system: System) -> SimulationSettings:
        p: Path = ("simulation",)
        spec = self.table(data.get("simulation", {}), p,
                          {"t_end", "samples", "method", "rtol", "atol", "y0", "yd0", "inputs"})
        kw: dict[str, Any] = {}
        checks = {"t_end": check_t_end, "rtol": check_rtol,
                  "atol": lambda v, name: check_atol(v, 1, name)[0],
                  "samples": lambda v, name: check_samples(v, system.f, len(system.inputs),
                                                           name)}
        for k, check in checks.items():
            if k in spec:
                v = self.number(spec[k], (*p, k), positive=True, integer=k == "samples")
                try:  # the bounds of jourdain.simulation.simulate, one place for the API and the files
                    kw[k] = check(v, k)
                except JourdainError as exc:
                    raise self.fail((*p, k), str(exc)) from None
        if "method" in spec:
            methods = ("DOP853", "RK45", "Radau", "BDF", "LSODA")
            m = self.string(spec["method"], (*p, "method"))
            if m not in methods:
                raise self.fail((*p, "method"), f'unknown method "{m}"'
                                f"{self.suggest(m, list(methods))}; expected one of "
                                f"{', '.join(methods)}")
            kw["method"] = m
        nums: set[str] = set()  # initial values are constant expressions (pi/4)
        for key in ("y0", "yd0"):
            tb = self.table(spec.get(key, {}), (*p, key), what="a table of coordinate = value")
            vals = {}
            for c, v in tb.items():
                cname = c[:-2] if key == "yd0" and c.endswith("_d") else c
                if cname not in self.coords:
                    raise self.fail((*p, key, c), f'"{c}" is not a declared coordinate'
                                    f"{self.suggest(c, self.coords)}")
                ex = self.expr(v, (*p, key, c), nums | set(self.params),
                               "initial values (numbers and parameters)")
                vals[cname] = float(ex.subs({se.Symbol(k): x for k, x in self.params.items()}))
            kw[key] = tuple(vals.get(c, 0.0) for c in self.coords)
        tb = self.table(spec.get("inputs", {}), (*p, "inputs"),
                        what="a table of input = expression in t")
        ins = []
        for iname, v in tb.items():
            if iname not in self.inputs:
                raise self.fail((*p, "inputs", iname), f'"{iname}" is not a declared input'
                                f"{self.suggest(iname, self.inputs)}")
            ins.append((iname, self.expr(v, (*p, "inputs", iname), set(self.params) | {"t"},
                                         "input laws (parameters and t)")))
        kw["inputs"] = tuple(ins)
        kw.setdefault("y0", tuple(0.0 for _ in self.coords))
        kw.setdefault("yd0", tuple(0.0 for _ in self.coords))
        return SimulationSettings(**kw)



def loads_model(text: str, filename: str = "<string>") -> ModelFile:
    """Read a model from TOML ``text``; ``filename`` is used in error messages."""
    return _Loader(text, filename).load()


def load_model(path: str | FsPath) -> ModelFile:
    """Read a model file. Raises :class:`ModelFileError` (a :class:`~jourdain.ModelError`)."""
    name = str(path)
    try:
        with open(path, "rb") as fh:
            # at most one byte more than allowed: a huge file (or /dev/zero) is not read whole
            raw = fh.read(MAX_FILE_BYTES + 1)
            size = len(raw)
            if size > MAX_FILE_BYTES:
                try:
                    size = max(size, os.fstat(fh.fileno()).st_size)
                except OSError:
                    pass
    except OSError as exc:
        raise ModelFileError(f"{name}: cannot read the model file: {exc.strerror}", name,
                             None) from None
    too_big = _too_big(size)
    if too_big:
        raise ModelFileError(f"{name}: {too_big}", name, None, (), too_big)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ModelFileError(f"{name}:{line}: the file is not valid UTF-8 text", name,
                             line) from None
    return loads_model(text, name)
