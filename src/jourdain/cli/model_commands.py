"""``jourdain check`` and ``jourdain eom``: the model validated and summarized, and its
symbolic equations (M̄, J̄, q̄^c, q̄^e; M, k, q) as text, LaTeX or JSON."""

from __future__ import annotations

import argparse
import json
from typing import Any

from ..analysis.reactions import check_reactions
from ..errors import JourdainError
from ..io import export
from ..workflow import check_initial_state, eom_matrices, has_capability, summary
from . import general
from .arguments import load

EXIT_OK = 0


def cmd_check(args: argparse.Namespace) -> int:
    model = load(args.model)
    if has_capability("reactions") and not model.system.groups:
        # the joints' constrained directions must satisfy the orthogonality J̄ᵀQ̄ = 0, joint by
        # joint and assembled (the numeric reactions' own checks, without the symbolic N̂);
        # an elastic body's reactions are not formed (jourdain.stages.reactions.checks)
        try:
            check_reactions(model.system.tree)  # the closing joints' rows: loop_summary
        except JourdainError as exc:
            raise model.error(str(exc)) from None
    check_initial_state(model)
    s = summary(model)
    if model.system.is_general:  # velocity constraints: the contacts, rows and speeds
        s["contacts"] = general.check_lines(model)
    loops = model.system if model.system.closing else None
    if loops is not None:  # closing joints (jourdain.loops): the loops and their mobility
        # jourdain.loops brings SciPy's linear algebra (0.2 s): imported for loop models only
        from ..loops.report import check_lines, loop_summary

        try:  # the assembly at the initial state, its rank and partition
            s["loops"] = loop_summary(model)
        except JourdainError as exc:  # located in the file, as every error of check
            raise model.error(f"the loops at the initial state: {exc}") from None
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
    if "contacts" in s:
        general.print_check(s["contacts"])
    return EXIT_OK



_TITLES = {
    "M_bar": "M̄ (global mass matrix, 6p×6p)", "J_bar": "J̄ (global Jacobian, 6p×f)",
    "q_c": "q̄^c (Coriolis, centrifugal and gyroscopic forces, 6p)",
    "q_e": "q̄^e (applied forces and torques, 6p)", "M": "M (mass matrix, f×f)",
    "k": "k (generalized gyroscopic forces, f)", "q": "q (generalized applied forces, f)",
    "Q_bar_c": "Q̄_c (the closing rows' constrained directions, 6p×r; J̄ᵀ·Q̄_c = Φ_yᵀ)",
    "Phi": "Φ (constraint rows of the closing joints, r)",
    "Phi_y": "Φ_y (their Jacobian ∂Φ/∂y, r×f)",
    "M_tree": "M_tree (the open tree's mass matrix, f×f)",
    "k_tree": "k_tree (the open tree's generalized gyroscopic forces, f)",
    "q_tree": "q_tree (the open tree's generalized applied forces, f)",
}
_LATEX = {"M_bar": r"\bar{M}", "J_bar": r"\bar{J}", "q_c": r"\bar{q}^{c}",
          "q_e": r"\bar{q}^{e}", "M": "M", "k": "k", "q": "q", "Q_bar_c": r"\bar{Q}_{c}",
          "Phi": r"\Phi", "Phi_y": r"\Phi_{y}", "M_tree": r"M_{\mathrm{tree}}",
          "k_tree": r"k_{\mathrm{tree}}", "q_tree": r"q_{\mathrm{tree}}"}


def closed_lines(system: Any) -> list[str]:
    """What the symbolic matrices of a closed system mean and how its equations of motion in
    the independent coordinates follow from them (in numbers: ``jourdain eval``)."""
    names = ", ".join(c.name for c in system.closing)
    ind = closure_independent(system)
    return [
        f"{system.name}: closed by the closing joint(s) {names}; the open tree's Newton–Euler "
        "equations M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g (Q̄ = [Q̄_tree, Q̄_c]: the tree joints' and the "
        "closing rows' constrained directions)",
        "  constraints Φ(y, t) = 0 with Φ_y; projected with J̄ of the tree: "
        "M_tree·ÿ + k_tree = q_tree + Φ_yᵀ·λ (λ: the multipliers, the closing rows' reactions)",
        f"  equations of motion in the independent coordinates {', '.join(ind)}: M·ÿ_i + k = q "
        "with ẏ = L·ẏ_i + l, ÿ = L·ÿ_i + γ, L = [E; −Φ_d⁻¹Φ_i], M = Lᵀ·M_tree·L, "
        "k = Lᵀ·(k_tree + M_tree·γ), q = Lᵀ·q_tree",
        "  M, k, q exist in numbers only (the dependent coordinates are implicit functions of "
        "the independent ones): jourdain eval gives them, with L, l, γ, λ and the reactions",
    ]


def closure_independent(system: Any) -> list[str]:
    """The independent coordinates of a closed system at its initial configuration."""
    try:
        return list(system.independent)
    except JourdainError:
        return []


def cmd_eom(args: argparse.Namespace) -> int:
    model = load(args.model)
    system = model.system
    if system.is_general:  # the symbolic rows and the tree's; M, k, q in z in numbers
        return general.cmd_eom(model, args, _TITLES, _LATEX)
    mats = eom_matrices(system)
    closed = bool(system.closing)
    # the expressions are in the tree's coordinates, rates and parameters
    symbols = system.tree if closed else system
    title = "Newton–Euler equations and equations of motion"
    if closed:
        title = "Newton–Euler equations of the tree, constraints and projected equations"
    if args.format == "json":
        data = {"format": "jourdain-eom/1", "model": system.name,
                "coordinates": system.coordinate_names,
                "rates": [f"{c}_d" for c in system.coordinate_names],
                "parameters": system.parameter_values, "inputs": system.input_names}
        if closed:
            con = system.constraints()
            data.update({"closing_joints": [c.name for c in system.closing],
                         "independent": closure_independent(system),
                         "constraint_labels": con.labels,
                         "equations": closed_lines(system)})
        data.update(export.matrices_json(mats, symbols))
        print(json.dumps(data, indent=1))
        return EXIT_OK
    if args.format == "latex":
        text = export.latex_fragment(mats, _LATEX, symbols,
                                     f"{system.name}: {title}".replace("–", "-"), args.max_ops)
        if closed:
            text = "".join(f"% {line}\n" for line in closed_lines(system)) + text
        print(text, end="")
        return EXIT_OK
    if closed:
        print("\n".join(closed_lines(system)))
    else:
        print(f"{system.name}: M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g  →  M·ÿ + k = q")
    frictions = getattr(system, "frictions", ())
    if frictions:  # they depend on the reactions: numbers only
        print(f"  joint friction ({', '.join(f.name for f in frictions)}) is not in these "
              "equations: it depends on the reactions and is solved with them in numbers "
              "(jourdain eval)")
    for k, m in mats.items():
        print(f"\n{_TITLES[k]} =")
        print(export.matrix_text(m, symbols, args.max_ops))
    return EXIT_OK
