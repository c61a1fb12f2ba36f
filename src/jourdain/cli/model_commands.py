"""``jourdain check`` and ``jourdain eom``: the model validated and summarized, and its
symbolic equations (M̄, J̄, q̄^c, q̄^e; M, k, q) as text, LaTeX or JSON."""

from __future__ import annotations

import argparse
import json

from ..analysis.reactions import check_reactions
from ..errors import JourdainError
from ..io import export
from ..workflow import check_initial_state, eom_matrices, has_capability, summary
from .arguments import load

EXIT_OK = 0


def cmd_check(args: argparse.Namespace) -> int:
    model = load(args.model)
    if has_capability("reactions"):
        # the joints' constrained directions must satisfy the orthogonality J̄ᵀQ̄ = 0, joint by
        # joint and assembled (the numeric reactions' own checks, without the symbolic N̂)
        try:
            check_reactions(model.system.tree)  # the closing joints' rows: loop_summary
        except JourdainError as exc:
            raise model.error(str(exc)) from None
    check_initial_state(model)
    s = summary(model)
    loops = model.system if model.system.closing else None
    if loops is not None:  # closing joints (jourdain.loops): the loops and their mobility
        # jourdain.loops brings SciPy's linear algebra (0.2 s): imported for loop models only
        from ..loops.report import check_lines, loop_summary

        s["loops"] = loop_summary(model)
    if args.json:
        print(json.dumps(s, indent=2))
        return EXIT_OK
    print(f"{args.model}: OK — {s['name']}")
    print(f"  degrees of freedom f = {s['degrees_of_freedom']}: {', '.join(s['coordinates'])}")
    print(f"  bodies p = {len(s['bodies'])}, Newton–Euler equations 6p = {6 * len(s['bodies'])}")
    print(f"  joints ({len(s['joints'])}), constrained directions q = {s['constraints']}:")
    for j in s["joints"]:
        coords = ", ".join(j["coordinates"]) or "—"
        dirs = ", ".join(j["constrained_directions"])
        print(f"    {j['name']:<14} {j['type']:<12} {j['parent']} → {j['body']}   "
              f"coordinates: {coords}; constrained: {j['constrained']}"
              + (f" ({dirs})" if dirs else ""))
    if s["forces"]:
        print("  force elements: " + ", ".join(f"{f['name']} ({f['type']})" for f in s["forces"]))
    if s["quantities"]:
        print("  kinematic quantities: " + "; ".join(
            f"{q['definition']} ({', '.join(q['symbols'])})" for q in s["quantities"]))
    if s["inputs"]:
        print("  inputs: " + ", ".join(s["inputs"]))
    print(f"  parameters ({len(s['parameters'])}): "
          + ", ".join(f"{k} = {v:g}" for k, v in s["parameters"].items()))
    if s["nominal_motions"]:
        print("  nominal motions: " + ", ".join(s["nominal_motions"]))
    if s["cyclic_coordinates"] and loops is None:  # the tree's, not the loop system's
        print(f"  cyclic coordinates: {', '.join(s['cyclic_coordinates'])} (in no equation, only "
              "their rates; stability verdicts are taken in Routh's sense without them)")
    if loops is not None:
        for line in check_lines(s["loops"]):
            print(line)
    return EXIT_OK



_TITLES = {
    "M_bar": "M̄ (global mass matrix, 6p×6p)", "J_bar": "J̄ (global Jacobian, 6p×f)",
    "q_c": "q̄^c (Coriolis, centrifugal and gyroscopic forces, 6p)",
    "q_e": "q̄^e (applied forces and torques, 6p)", "M": "M (mass matrix, f×f)",
    "k": "k (generalized gyroscopic forces, f)", "q": "q (generalized applied forces, f)",
}


def cmd_eom(args: argparse.Namespace) -> int:
    model = load(args.model)
    system = model.system
    mats = eom_matrices(system)
    if args.format == "json":
        data = {"format": "jourdain-eom/1", "model": system.name,
                "coordinates": system.coordinate_names,
                "rates": [f"{c}_d" for c in system.coordinate_names],
                "parameters": system.parameter_values, "inputs": system.input_names}
        data.update(export.matrices_json(mats, system))
        print(json.dumps(data, indent=1))
        return EXIT_OK
    if args.format == "latex":
        names = {"M_bar": r"\bar{M}", "J_bar": r"\bar{J}", "q_c": r"\bar{q}^{c}",
                 "q_e": r"\bar{q}^{e}", "M": "M", "k": "k", "q": "q"}
        print(export.latex_fragment(
            mats, names, system, f"{system.name}: Newton-Euler equations and equations of motion",
            args.max_ops), end="")
        return EXIT_OK
    print(f"{system.name}: M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g  →  M·ÿ + k = q")
    for k, m in mats.items():
        print(f"\n{_TITLES[k]} =")
        print(export.matrix_text(m, system, args.max_ops))
    return EXIT_OK

