"""The commands on a *general* system (velocity constraints, ``docs/rolling.md``): ``check``,
``eval`` (``--json``: the ``jourdain-eval/1`` document with the speeds, L, L̄ and the contact
forces), ``reactions`` (contact forces by element, normal and tangential), ``linearize`` (about
the file's nominal steady motion: M̃, P, Q, D, G, K, N, eigenvalues, the verdict, the cyclic
coordinates left out) and ``eom``. Each command calls this module's function for a system
with contacts instead of the tree's path, so none of them can give the open tree's numbers;
``simulate`` shares the tree's path (``System.simulate`` runs the general system).
"""

from __future__ import annotations

import argparse
import json
from typing import Any

import numpy as np

from ..analysis.modes import stability
from ..errors import JourdainError
from ..io import export
from ..io.capabilities import steady_mapping
from ..workflow.evaluation import EVAL_FORMAT, json_array
from .arguments import overrides, state_at

EXIT_OK = 0


#: the symbolic matrices of a general system that eom shows beyond the closed system's
TITLES = {
    "A": "A (every constraint row at the velocity level, A·ẏ + a = 0, r×f)",
    "a": "a (their part without ẏ, r)",
    "Q_bar_c": "Q̄_c (the rows' constrained directions, 6p×r; J̄ᵀ·Q̄_c = Aᵀ)",
    "Phi": "Φ (the holonomic rows, r_h)",
}
LATEX = {"A": "A", "a": "a"}


def eom_lines(system: Any) -> list[str]:
    """What a general system's symbolic matrices mean and how its equations in z follow."""
    con = system.constraints()
    speeds = ", ".join(n for n, _ in system.speeds) if system.speeds else "chosen by pivoting"
    return [
        f"{system.name}: constrained by the contact(s) {', '.join(c.name for c in system.contacts)}"
        "; the open tree's Newton–Euler equations M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g (Q̄ = [Q̄_tree, "
        "Q̄_c]: the tree joints' and the contact rows' constrained directions)",
        f"  rows ({con.r}: {', '.join(con.labels)}) at the velocity level A·ẏ + a = 0; "
        "projected with J̄ of the tree: M_tree·ÿ + k_tree = q_tree + Aᵀ·λ (λ: the contact forces)",
        f"  speeds z ({speeds}) = Y·ẏ + b; W = [Y; A]: ẏ = L·z + l, ÿ = L·ż + γ; equations "
        "of motion M·ż + k = q with M = Lᵀ·M_tree·L, k = Lᵀ·(k_tree + M_tree·γ), q = Lᵀ·q_tree",
        "  M, k, q exist in numbers only (W is solved at a state): jourdain eval gives them, with "
        "L, l, γ and the contact forces",
    ]


def eom_matrices(system: Any) -> dict[str, Any]:
    """The symbolic matrices of a general system: the tree's M̄, J̄, q̄^c, q̄^e, the rows' A, a,
    Φ, Q̄_c and the tree's projected M, k, q."""
    eom = system.tree.equations_of_motion()
    ne = eom.newton_euler
    con = system.constraints()
    return {"M_bar": ne.M_bar, "J_bar": ne.J_bar, "q_c": ne.q_c, "q_e": ne.q_e,
            "A": con.A, "a": con.a, "Phi": con.Phi, "Q_bar_c": con.Q_bar,
            "M_tree": eom.M, "k_tree": eom.k, "q_tree": eom.q}


def cmd_eom(model: Any, args: argparse.Namespace, titles: dict[str, str],
            latex: dict[str, str]) -> int:
    """``jourdain eom`` of a general system: :func:`eom_matrices` with :func:`eom_lines`."""
    system = model.system
    mats = eom_matrices(system)
    symbols = system.tree
    lines = eom_lines(system)
    if args.format == "json":
        data = {"format": "jourdain-eom/1", "model": system.name,
                "coordinates": system.coordinate_names,
                "rates": [f"{c}_d" for c in system.coordinate_names],
                "parameters": system.parameter_values, "inputs": system.input_names,
                "contacts": [c.name for c in system.contacts],
                "constraint_labels": system.constraints().labels, "equations": lines}
        data.update(export.matrices_json(mats, symbols))
        print(json.dumps(data, indent=1))
        return EXIT_OK
    if args.format == "latex":
        text = export.latex_fragment(mats, {**latex, **LATEX}, symbols,
                                     f"{system.name}: Newton-Euler equations of the tree, "
                                     "constraint rows and projected equations", args.max_ops)
        print("".join(f"% {line}\n" for line in lines) + text, end="")
        return EXIT_OK
    print("\n".join(lines))
    for k, m in mats.items():
        print(f"\n{({**titles, **TITLES})[k]} =")
        print(export.matrix_text(m, symbols, args.max_ops))
    return EXIT_OK


def _evaluate(model: Any, args: argparse.Namespace) -> tuple[dict[str, Any], dict, float]:
    system = model.system
    params = overrides(system, args.set)
    y, yd, t, inputs = state_at(model, args.at)
    if inputs and any(v != 0 for v in inputs.values()):
        raise JourdainError(f"{system.name}: inputs are not available for systems with "
                            "velocity constraints yet")
    try:
        out = system.evaluate(y, yd, t=t, parameters=params or None)
    except JourdainError as exc:
        raise model.error(str(exc)) from None
    pv = system.parameter_values
    pv.update(params)
    return out, pv, t


def check_lines(model: Any) -> dict[str, Any]:
    """What ``check`` adds for a general system: its contacts, rows, speeds and the state
    assembled at the initial values (the rows' residuals there)."""
    system = model.system
    con = system.constraints()
    sim = model.simulation
    y0 = np.asarray(sim.y0 if len(sim.y0) else np.zeros(system.f), dtype=float)
    yd0 = np.asarray(sim.yd0 if len(sim.yd0) else np.zeros(system.f), dtype=float)
    try:
        out = system.evaluate(y0, yd0)
    except JourdainError as exc:
        raise model.error(f"the contacts at the initial state: {exc}") from None
    return {"contacts": [c.name for c in system.contacts], "rows": con.labels,
            "holonomic_rows": con.r_h, "velocity_rows": con.r - con.r_h,
            "speeds": out["speeds"], "independent": out["independent"],
            "residual": {"Phi": float(np.max(np.abs(out["Phi"]), initial=0.0)),
                         "A_yd_plus_a": float(np.max(np.abs(out["Phi_dot"]), initial=0.0))},
            "orthogonality": out["orthogonality"]}


def print_check(info: dict[str, Any]) -> None:
    print(f"  contacts: {', '.join(info['contacts'])} ({info['holonomic_rows']} holonomic and "
          f"{info['velocity_rows']} velocity rows: {', '.join(info['rows'])})")
    print(f"  generalized velocities z ({len(info['speeds'])}): {', '.join(info['speeds'])}; "
          f"independent coordinates: {', '.join(info['independent'])}")
    r = info["residual"]
    print(f"  at the initial state: |Φ| = {r['Phi']:.3g}, |A·ẏ + a| = {r['A_yd_plus_a']:.3g}, "
          f"max |L̄ᵀ·Q̄_c| = {info['orthogonality']:.3g}")


def cmd_eval(model: Any, args: argparse.Namespace) -> int:
    system = model.system
    out, pv, t = _evaluate(model, args)
    names = ("M", "k", "q", "z", "zd", "L", "l", "y", "yd", "ydd", "M_bar", "J_bar", "Q_c",
             "lambda", "Phi", "Phi_dot")
    if args.json:
        doc = {"format": EVAL_FORMAT, "model": system.name, "file": model.path,
               "coordinates": system.coordinate_names, "t": t,
               "y": np.asarray(out["y"]).tolist(), "yd": np.asarray(out["yd"]).tolist(),
               "parameters": pv, "inputs": {},
               "values": {k: json_array(np.asarray(out[k], dtype=float)) for k in names},
               "speeds": out["speeds"], "independent": out["independent"],
               "constraint_labels": out["labels"], "contact_forces": out["contact_forces"],
               "contacts_undetermined": out["contacts_undetermined"],
               "orthogonality": out["orthogonality"], "g_names": [], "g_undetermined": [],
               "not_available": {k: "a general system's joint reactions are not formed yet "
                                 "(its contact forces are under contact_forces)"
                                 for k in ("Q_bar", "N_hat", "k_hat", "q_hat", "g")}}
        print(json.dumps(doc, indent=1))
        return EXIT_OK
    print(f"{system.name} at t = {t:g}: "
          + ", ".join(f"{n}={v:.6g}" for n, v in zip(system.coordinate_names, out["y"],
                                                     strict=True)))
    print(f"  speeds z = ({', '.join(out['speeds'])}) = {np.array2string(out['z'])}, "
          f"ż = {np.array2string(out['zd'])}")
    with np.printoptions(precision=6, suppress=False, linewidth=100):
        for k in ("M", "k", "q", "L"):
            print(f"\n{k} =\n{np.asarray(out[k])}")
    _print_forces(out)
    return EXIT_OK


def _print_forces(out: dict[str, Any]) -> None:
    print("\ncontact forces (along each row's direction, on the body at the contact point):")
    und = set(out["contacts_undetermined"])
    for lab, v in out["contact_forces"].items():
        print(f"  {lab:16s} {v: .6g}" + ("   (shared with a redundant row)" if lab in und
                                          else ""))


def cmd_reactions(model: Any, args: argparse.Namespace) -> int:
    out, _, t = _evaluate(model, args)
    print(f"{model.system.name} at t = {t:g}: .N normal, .T1/.T2 along the ground's axes, .T "
          "across a knife edge")
    _print_forces(out)
    return EXIT_OK


def linear_result(model: Any, about: str | None, params: dict[str, float]) -> Any:
    """The linearization about the file's nominal motion ``about`` (default the first)."""
    system = model.system
    if not model.nominal:
        raise model.error("linearize: the model has no [nominal.<name>] steady motion")
    nom = next((n for n in model.nominal if n.name == about), model.nominal[0])
    mapping = steady_mapping(system, nom)
    try:
        lin = system.linearize(mapping).at(params) if params else system.linearize(mapping)
    except JourdainError as exc:
        raise model.error(f'nominal "{nom.name}": {exc}') from None
    return nom.name, lin


def cmd_linearize(model: Any, args: argparse.Namespace) -> int:
    system = model.system
    params = overrides(system, args.set)
    name, lin = linear_result(model, args.about, params)
    st = stability(lin)
    if args.json:
        doc = {"model": system.name, "nominal": name, "coordinates": list(lin.names),
               "speeds": list(lin.speeds), "cyclic": list(lin.cyclic),
               "parameters": dict(lin.parameters or {}),
               **{k: json_array(np.asarray(getattr(lin, k))) for k in
                  ("M_tilde", "P", "Q", "h", "D", "G", "K", "N")},
               "eigenvalues": {"real": lin.eigenvalues.real.tolist(),
                               "imag": lin.eigenvalues.imag.tolist()},
               "verdict": st.verdict}
        print(json.dumps(doc, indent=1))
        return EXIT_OK
    print(f"{system.name}: linearized about \"{name}\" in η = ({', '.join(lin.names)}); "
          f"cyclic, left out: {', '.join(lin.cyclic) or 'none'}")
    with np.printoptions(precision=8, suppress=False, linewidth=100):
        for k in ("M_tilde", "D", "G", "K", "N"):
            print(f"\n{k} =\n{np.asarray(getattr(lin, k))}")
        print(f"\neigenvalues: {np.array2string(lin.eigenvalues)}")
    print(f"verdict: {st.verdict}")
    return EXIT_OK


__all__ = ["check_lines", "cmd_eom", "cmd_eval", "cmd_linearize", "cmd_reactions", "eom_lines",
           "eom_matrices", "linear_result", "print_check"]
