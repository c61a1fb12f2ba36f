"""``jourdain linearize`` on a loop model (the command line dispatches here for models with
closing joints): the linearization in the independent coordinates about the equilibrium
nearest the model file's initial configuration (:func:`jourdain.loops.linearization.equilibrium`;
exact: :func:`~jourdain.loops.linearization.linearize_loop_exact`), or about the initial
configuration at rest where no equilibrium is found nearby (finite differences).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import JourdainError
from ..model import System
from .linearization import (
    LoopLinearization,
    equilibrium,
    linearize_loop,
    linearize_loop_exact,
)


def linearize_near(loop: System, z0: Any,
                   parameters: Mapping[str, float] | None = None
                   ) -> tuple[LoopLinearization, str]:
    """The linearization about the equilibrium nearest ``z0``, else about ``z0`` at rest;
    with the words saying which."""
    try:
        z_s = equilibrium(loop, z0, parameters=parameters)
    except JourdainError as exc:
        about = f"initial configuration at rest (no equilibrium: {exc})"
        return linearize_loop(loop, np.asarray(z0, dtype=float), parameters=parameters), about
    # at an equilibrium the symbolic derivatives apply (the exact linearization)
    return (linearize_loop_exact(loop, z_s, parameters=parameters),
            "equilibrium nearest the initial configuration")


def linearize_document(model: Any, parameters: Mapping[str, float] | None = None
                       ) -> dict[str, Any]:
    """The linearization of the loop model ``model`` (a model file's, with ``.loops`` and
    ``.simulation``) as a JSON-able document."""
    loop: System = model.system
    lin, about = linearize_near(loop, model.simulation.y0, parameters)
    return linearization_document(loop, lin, about)


def linearization_document(loop: System, lin: LoopLinearization, about: str
                           ) -> dict[str, Any]:
    """A linearization of :func:`linearize_near` as a JSON-able document."""
    ev = lin.eigenvalues

    def mat(a: np.ndarray) -> list:
        return np.asarray(a, dtype=float).tolist()
    return {
        "model": loop.name, "about": about, "independent": list(lin.names),
        "z_s": dict(zip(loop.coordinate_names, lin.z_s.tolist(), strict=True)),
        "M_tilde": mat(lin.M_tilde), "P": mat(lin.P), "Q": mat(lin.Q), "h": mat(lin.h),
        "D": mat(lin.D), "G": mat(lin.G), "K": mat(lin.K), "N": mat(lin.N),
        "eigenvalues": [[float(v.real), float(v.imag)] for v in ev],
        "frequencies_hz": sorted({round(abs(float(v.imag)) / (2 * math.pi), 12)
                                  for v in ev if v.imag > 0}),
        "stable": bool(np.all(ev.real < 0)),
        "method": ("symbolic derivatives of the tree's k, q and of Φ (with the constraint "
                   "forces' geometric stiffness), projected with J_z"
                   if about.startswith("equilibrium") else
                   "central differences of the compiled M, k, q in the independent "
                   "coordinates"),
    }


def linearize_text(doc: Mapping[str, Any]) -> str:
    """The document of :func:`linearize_document` as text."""
    names = doc["independent"]
    lines = [f"{doc['model']}: linearization in the independent coordinates "
             f"{', '.join(names)}", f"  about the {doc['about']}:",
             "  " + ", ".join(f"{k} = {v:.6g}" for k, v in doc["z_s"].items())]
    for key in ("M_tilde", "D", "G", "K", "N"):
        rows = np.asarray(doc[key])
        lines.append(f"  {key} =")
        lines.extend("    [" + ", ".join(f"{x: .6g}" for x in r) + "]" for r in rows)
    lines.append("  eigenvalues: " + ", ".join(f"{re:.6g}{im:+.6g}j"
                                               for re, im in doc["eigenvalues"]))
    if doc["frequencies_hz"]:
        lines.append("  frequencies: " + ", ".join(f"{f:.6g} Hz"
                                                   for f in doc["frequencies_hz"]))
    lines.append("  asymptotically stable" if doc["stable"] else
                 "  not asymptotically stable (an eigenvalue with real part ≥ 0)")
    lines.append(f"  ({doc['method']})")
    return "\n".join(lines)


def linearize_command(model: Any, parameters: Mapping[str, float], as_json: bool,
                      about: str | None = None) -> int:
    """``jourdain linearize`` for a loop model; prints and returns the exit status 0."""
    if about is not None:
        raise JourdainError(f"{model.path}: --about: a loop model is linearized about its "
                            "equilibrium nearest the initial configuration (nominal motions "
                            "of loop models are not supported)")
    doc = linearize_document(model, parameters or None)
    print(json.dumps(doc, indent=1) if as_json else linearize_text(doc))
    return 0


__all__ = ["linearization_document", "linearize_command", "linearize_document", "linearize_near", "linearize_text"]
