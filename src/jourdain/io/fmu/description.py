"""The variables of an exported FMU and its ``modelDescription.xml`` (FMI 2.0).

Value references, in this order (the same as ``fmi2.c``):

====================  ============================  =========================================
value reference       variable                      FMI causality / variability / initial
====================  ============================  =========================================
0                     ``time``                      independent
1 … f                 coordinates ``y``             output, continuous, exact (a state)
f+1 … 2f              rates ``<y>_d``               output, continuous, exact (a state)
2f+1 … 3f             ``der(<y>)`` = ẏ              local, continuous, calculated
3f+1 … 4f             ``der(<y>_d)`` = ÿ            local, continuous, calculated
then                  parameters                    parameter, tunable, exact
then                  inputs                        input, continuous (start 0)
then                  reaction components g         output, continuous, calculated
then                  a closed system's outputs     output, continuous, calculated
====================  ============================  =========================================

A closed system (closing joints) has its independent coordinates as ``y`` (f of the tree's n);
its outputs after the reactions are the dependent coordinates, their rates ``<d>_d`` and the
closure residuals ``Phi.<row>`` (one per constraint row of the closing joints).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from .units import base_unit, is_si

_STRUCTURED = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*\Z")


@dataclass(frozen=True)
class Variable:
    """One scalar variable of the FMU (value reference = its position in the list)."""

    name: str
    causality: str
    variability: str
    initial: str | None = None
    start: float | None = None
    unit: str | None = None
    description: str = ""
    #: 1-based index of the state variable this one is the derivative of
    derivative: int | None = None


@dataclass(frozen=True)
class Layout:
    """The variables and what ``model.h`` needs to know about them."""

    variables: tuple[Variable, ...]
    f: int
    n_p: int
    n_u: int
    reactions: tuple[str, ...]
    #: a closed system's outputs after the reactions (dependent coordinates, rates, Φ)
    n_out: int = 0

    def index(self, name: str) -> int:
        """1-based index of a variable in ModelVariables."""
        for i, v in enumerate(self.variables):
            if v.name == name:
                return i + 1
        raise KeyError(name)


def reaction_unit(name: str) -> str | None:
    """N for the force components ``<joint>.F_*``, N*m for the torques ``<joint>.T_*``."""
    suffix = name.rsplit(".", 1)[-1]
    if suffix.startswith("F_"):
        return "N"
    if suffix.startswith("T_"):
        return "N*m"
    return None


def layout(coordinates: Sequence[str], parameters: Mapping[str, float], inputs: Sequence[str],
           reactions: Sequence[str], y0: Sequence[float], yd0: Sequence[float],
           units: Mapping[str, str], descriptions: Mapping[str, str],
           outputs: Sequence[tuple[str, str | None, str]] = ()) -> Layout:
    """The variables of the FMU in value-reference order (see the module docstring).

    ``outputs``: (name, unit, description) of further outputs (a closed system's).
    Reaction components get N and N·m where the model's units are coherent SI ones (every
    coordinate in m or rad and every parameter unit of factor 1), since jourdain does not
    convert units and the forces come out in the units the model's numbers imply.
    """
    f = len(coordinates)
    si = (all(units.get(c) in ("m", "rad") for c in coordinates)
          and all(is_si(units[p]) for p in parameters if p in units))
    vs: list[Variable] = [Variable("time", "independent", "continuous",
                                   description="time", unit="s" if units else None)]
    for c, v in zip(coordinates, y0, strict=True):
        vs.append(Variable(c, "output", "continuous", "exact", float(v), units.get(c),
                           descriptions.get(c, f"coordinate {c}")))
    for c, v in zip(coordinates, yd0, strict=True):
        u = units.get(c)
        vs.append(Variable(f"{c}_d", "output", "continuous", "exact", float(v),
                           f"{u}/s" if u else None, f"rate of {c}"))
    for i, c in enumerate(coordinates):
        u = units.get(c)
        vs.append(Variable(f"der({c})", "local", "continuous", "calculated", None,
                           f"{u}/s" if u else None, f"time derivative of {c} (= {c}_d)",
                           derivative=2 + i))
    for i, c in enumerate(coordinates):
        u = units.get(c)
        vs.append(Variable(f"der({c}_d)", "local", "continuous", "calculated", None,
                           f"{u}/s^2" if u else None, f"acceleration of {c}",
                           derivative=2 + f + i))
    for p, v in parameters.items():
        vs.append(Variable(p, "parameter", "tunable", "exact", float(v), units.get(p),
                           descriptions.get(p, "")))
    for u_ in inputs:
        vs.append(Variable(u_, "input", "continuous", None, 0.0, units.get(u_),
                           descriptions.get(u_, "")))
    for g in reactions:
        vs.append(Variable(g, "output", "continuous", "calculated", None,
                           reaction_unit(g) if si else None,
                           f"reaction component {g} (child frame at the joint point)"))
    for name, unit, text in outputs:
        vs.append(Variable(name, "output", "continuous", "calculated", None, unit, text))
    return Layout(tuple(vs), f, len(parameters), len(inputs), tuple(reactions), len(outputs))


def _g(x: float) -> str:
    return repr(float(x))


def model_description(lay: Layout, *, model_name: str, model_identifier: str, guid: str,
                      description: str, version: str, sources: Sequence[str],
                      start_time: float, stop_time: float, tolerance: float,
                      step_size: float | None) -> str:
    """``modelDescription.xml`` of an FMU for model exchange and co-simulation."""
    names = [v.name for v in lay.variables]
    plain = [n[4:-1] if n.startswith("der(") and n.endswith(")") else n for n in names]
    convention = "structured" if all(_STRUCTURED.match(n) for n in plain) else "flat"
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": model_name, "guid": guid,
        "description": description, "generationTool": f"jourdain {version}",
        "variableNamingConvention": convention, "numberOfEventIndicators": "0"})
    if not description:
        del root.attrib["description"]
    common = {"modelIdentifier": model_identifier, "canGetAndSetFMUstate": "true",
              "canSerializeFMUstate": "true", "providesDirectionalDerivative": "false"}
    me = ET.SubElement(root, "ModelExchange", {**common,
                                                "completedIntegratorStepNotNeeded": "true"})
    cs = ET.SubElement(root, "CoSimulation", {
        **common, "canHandleVariableCommunicationStepSize": "true",
        "canInterpolateInputs": "true", "maxOutputDerivativeOrder": "0"})
    for kind in (me, cs):
        files = ET.SubElement(kind, "SourceFiles")
        for s in sources:
            ET.SubElement(files, "File", {"name": s})
    units = sorted({v.unit for v in lay.variables if v.unit})
    if units:
        defs = ET.SubElement(root, "UnitDefinitions")
        for u in units:
            el = ET.SubElement(defs, "Unit", {"name": u})
            b = base_unit(u)
            if b is not None:
                ET.SubElement(el, "BaseUnit", b.attributes())
    cats = ET.SubElement(root, "LogCategories")
    ET.SubElement(cats, "Category", {"name": "logStatusError",
                                     "description": "errors: the model could not be evaluated"})
    ET.SubElement(cats, "Category", {"name": "logAll", "description": "all messages"})
    exp = {"startTime": _g(start_time), "stopTime": _g(stop_time), "tolerance": _g(tolerance)}
    if step_size:
        exp["stepSize"] = _g(step_size)
    ET.SubElement(root, "DefaultExperiment", exp)
    mv = ET.SubElement(root, "ModelVariables")
    for vr, v in enumerate(lay.variables):
        attrs = {"name": v.name, "valueReference": str(vr)}
        if v.description:
            attrs["description"] = v.description
        attrs["causality"] = v.causality
        attrs["variability"] = v.variability
        if v.initial is not None and v.causality not in ("input", "independent"):
            attrs["initial"] = v.initial
        sv = ET.SubElement(mv, "ScalarVariable", attrs)
        real: dict[str, str] = {}
        if v.unit:
            real["unit"] = v.unit
        if v.start is not None:
            real["start"] = _g(v.start)
        if v.derivative is not None:
            real["derivative"] = str(v.derivative)
        ET.SubElement(sv, "Real", real)
    ms = ET.SubElement(root, "ModelStructure")
    outputs = ET.SubElement(ms, "Outputs")
    for i, v in enumerate(lay.variables):
        if v.causality == "output":
            ET.SubElement(outputs, "Unknown", {"index": str(i + 1)})
    ders = ET.SubElement(ms, "Derivatives")
    for i, v in enumerate(lay.variables):
        if v.derivative is not None:
            ET.SubElement(ders, "Unknown", {"index": str(i + 1)})
    init = ET.SubElement(ms, "InitialUnknowns")
    for i, v in enumerate(lay.variables):
        if v.initial == "calculated" and (v.causality == "output" or v.derivative is not None):
            ET.SubElement(init, "Unknown", {"index": str(i + 1)})
    ET.indent(root, "  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, "unicode") + "\n"


def build_description(model_identifier: str, sources: Sequence[str]) -> str:
    """``sources/buildDescription.xml`` (the FMI 3.0 format that FMI 2.0.4 adopts)."""
    root = ET.Element("fmiBuildDescription", {"fmiVersion": "3.0"})
    conf = ET.SubElement(root, "BuildConfiguration", {"modelIdentifier": model_identifier})
    fs = ET.SubElement(conf, "SourceFileSet", {"language": "C99"})
    for s in sources:
        ET.SubElement(fs, "SourceFile", {"name": s})
    ET.SubElement(conf, "Library", {"name": "m"})
    ET.indent(root, "  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, "unicode") + "\n"
