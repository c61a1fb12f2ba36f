"""The report of a closed system (a model with closing joints, METHOD.md §7): the same sections
as a tree's, with the closed system's numbers, plus section 6, "Closed loops".

* section 2 (the symbolic equations) says why it is not shown: the velocity map
  ``ẏ = L·ẏ_i + l`` of a closed system exists in numbers only;
* section 3: M, k, q in the independent coordinates and every joint's reactions g (the
  closing joints' rows included) from :meth:`jourdain.System.evaluate` at the assembled
  initial state (``values.json``: the closed M, k, q, not the open tree's);
* section 4: the linearization in the independent coordinates
  (:meth:`jourdain.System.linearize`) about the equilibrium nearest the initial configuration,
  else about the initial configuration at rest (``linearization-equilibrium.json``);
* section 5: the tree report's simulation section with :meth:`jourdain.System.simulate`'s
  motion on the manifold (the mechanism drawn closed: the closing joints' points joined);
* section 6: the closing joints, the constraint rows, the degrees of freedom by Grübler's
  count and by the rank of Φ_y, the partitions used along the run, the closure residuals
  max|Φ| and max|Φ̇| along the motion and the closing joints' reactions
  (``wrench-<closing joint>.csv``, ``loops.csv``: Φ, Φ̇ and λ by row, ``loops.json``).
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from ...analysis.modes import stability
from ...errors import JourdainError
from ...numeric import parameter_vector
from .figures import eigen_plot, time_plot
from .html import SYM, esc, html_table, mathml, matrix_table, note, numstr, snap
from .state import Run

#: the heading of section 2 (the tree report's)
EQUATIONS_HEADING = "<h2>2. Newton–Euler equations and equations of motion</h2>"


def closing_names(system: Any) -> str:
    return ", ".join(c.name for c in system.closing)


def equations_section(run: Run) -> str:
    """Section 2 of a closed system: why the symbolic equations are not shown."""
    system = run.model.system
    run.info.notes.append("equations: not available for a closed system (numbers only)")
    return (EQUATIONS_HEADING
            + note(f"the symbolic Newton–Euler equations and equations of motion are not "
                   f"shown: {system.name!r} is closed by {closing_names(system)}, and the "
                   "equations of motion of a closed system need its velocity map "
                   "ẏ = L·ẏ_i + l, which exists in numbers only (coordinate partitioning at "
                   "a configuration); sections 3 and 4 give them in numbers in the "
                   "independent coordinates, section 6 the closing joints' constraints")
            + "<p class='meta'>No equations.tex and equations.json for a closed system.</p>")


def assembled_state(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """The model's initial state (the tree's coordinates as the file gives them)."""
    sim = run.model.simulation
    f = run.model.system.f
    y0 = np.array(sim.y0 or [0.0] * f, float)
    yd0 = np.array(sim.yd0 or [0.0] * f, float)
    return y0, yd0


def numbers_rows(run: Run, values: dict[str, np.ndarray], extra: dict[str, Any]) -> list[str]:
    """M, k, q in the independent coordinates, the velocity map L and the reactions."""
    system = run.model.system
    ind = list(extra.get("independent", system.independent or ()))
    coords = system.coordinate_names
    s = [f"<p>Assembled on Φ = 0, Φ̇ = 0 with the independent coordinates "
         f"{esc(', '.join(ind))} held: "
         + ", ".join(f"{esc(c)} = {numstr(v)}" for c, v in zip(coords, values["y"], strict=True))
         + "; " + ", ".join(f"{esc(c)}_d = {numstr(v)}"
                            for c, v in zip(coords, values["yd"], strict=True))
         + ". M, k, q in the independent coordinates (M = LᵀM_tree·L, k = Lᵀ(k_tree + "
           "M_tree·γ), q = Lᵀq_tree with ẏ = L·ẏ_i + l).</p>"]
    for k in ("M", "k", "q"):
        s.append(f"<h3>{mathml(SYM[k], False)}</h3>"
                 + matrix_table(values[k], ind, ind if k == "M" else None))
    if "L" in values:
        s.append("<h3>Velocity map L (ẏ = L·ẏ<sub>i</sub> + l)</h3>"
                 + matrix_table(values["L"], coords, ind))
    return s


def linearization_section(run: Run) -> str:
    """Section 4 of a closed system: M̃, P, Q, h, D, G, K, N and the eigenvalues in the
    independent coordinates about the equilibrium nearest the initial configuration (else the
    initial configuration at rest)."""
    from ..closed_linear import linearization_document, linearize_near

    model, out, info = run.model, run.out, run.info
    system = model.system
    s = ["<h2>4. Linearization, eigenvalues and stability</h2>",
         "<p>M̃·η̈ + P·η̇ + Q·η = h in the independent coordinates of the closed system, with "
         "D = ½(P + Pᵀ) (damping), G = ½(P − Pᵀ) (gyroscopic), K = ½(Q + Qᵀ) (stiffness), "
         "N = ½(Q − Qᵀ) (circulatory).</p>"]
    if model.nominal:
        s.append(note("the nominal motions of the model file are not linearized for a closed "
                      "system: it is linearized about the state below"))
    y0, _ = assembled_state(run)
    params = run.params or None
    try:
        lin, about = linearize_near(system, y0, params)
    except (JourdainError, np.linalg.LinAlgError) as exc:
        s.append(note(f"could not linearize: {exc}"))
        info.notes.append(f"linearization: {exc}")
        return "".join(s)
    names = list(lin.names)
    s.append(f"<h3>About the {esc(about)}</h3><p>"
             + ", ".join(f"{esc(c)} = {numstr(v)}" for c, v in
                         zip(system.coordinate_names, lin.z_s, strict=True)) + "</p>")
    for k in ("M_tilde", "P", "Q", "h", "D", "G", "K", "N"):
        v = np.asarray(getattr(lin, k), float)
        s.append(f"<h4>{mathml(SYM[k], False)}</h4>"
                 + matrix_table(v, names, names if v.ndim == 2 else None))
    ev = np.asarray(lin.eigenvalues, complex)
    lams = snap(ev, 1e-9)
    rows = []
    for lam in lams:
        w = abs(lam)
        rows.append((numstr(lam.real), numstr(lam.imag), numstr(w / (2 * np.pi)),
                     numstr(-lam.real / w) if w > 0 else "—"))
    s.append(html_table(rows, ["Re λ / (1/s)", "Im λ / (rad/s)", "f<sub>n</sub> / Hz", "ζ"]))
    s.append(run.figures.add(eigen_plot, lams, "eigenvalues about the equilibrium"))
    st = stability(lin.state_space(), cyclic=())  # the verdict of trees and of the CLI
    cls = "ok" if st.is_stable else "bad"
    s.append(f"<p>Stability: <span class='{cls}'>{esc(st.verdict)}</span> — "
             f"{esc(st.reason)}</p>")
    info.summary_lines.append(f"  linearized about the {about.split(' (')[0]}: {st.verdict}")
    doc = linearization_document(system, lin, about)
    fn = out / "linearization-equilibrium.json"
    fn.write_text(json.dumps(doc, indent=1), encoding="utf-8")
    info.files.append(fn)
    return "".join(s)


def loops_section(run: Run, res: Any) -> str:
    """Section 6: the closing joints, constraint rows, degrees of freedom, partitions, the
    closure residuals and the closing joints' reactions along the motion ``res`` (None: no
    motion)."""
    from ...loops.report import loop_summary

    model, out, info = run.model, run.out, run.info
    system = model.system
    s = ["<h2>6. Closed loops</h2>"]
    try:
        summ = loop_summary(model)
    except JourdainError as exc:
        s.append(note(f"the loops' summary is not available: {exc}"))
        info.notes.append(f"closed loops: {exc}")
        summ = None
    s.append("<h3>Closing joints</h3>" + html_table(
        [(esc(c.name), esc(c.type), esc(c.body_a), esc(c.body_b)) for c in system.closing],
        ["closing joint", "type", "body A", "body B"], "info"))
    doc: dict[str, Any] = {"name": system.name,
                           "closing_joints": [c.name for c in system.closing]}
    if summ is not None:
        rows = summ["constraint_rows"]
        s.append(f"<p>{len(rows)} constraint equations Φ = 0: {esc(', '.join(rows))}.</p>")
        planar = summ["degrees_of_freedom_grubler_planar"]
        s.append(html_table(
            [("tree coordinates", str(len(summ["tree_coordinates"]))),
             ("Grübler (spatial)", str(summ["degrees_of_freedom_grubler_spatial"])),
             ("Grübler (planar)", "—" if planar is None else str(planar)),
             ("rank of Φ_y at the assembled initial configuration", str(summ["rank_Phi_y"])),
             ("degrees of freedom by the rank", str(summ["degrees_of_freedom_rank"])),
             ("independent (initial partition)", esc(", ".join(summ["independent"]))),
             ("dependent", esc(", ".join(summ["dependent"]))),
             ("cond Φ_d", numstr(summ["cond_Phi_d"])),
             ("assembly residual |Φ|", numstr(summ["assembly_residual"]["Phi"])),
             ("assembly residual |Φ̇|", numstr(summ["assembly_residual"]["Phi_dot"]))],
            ["", "value"], "info"))
        doc.update({k: summ[k] for k in (
            "constraint_rows", "degrees_of_freedom_grubler_spatial",
            "degrees_of_freedom_grubler_planar", "degrees_of_freedom_rank", "rank_Phi_y",
            "independent", "dependent", "cond_Phi_d")})
    if res is None or len(res.t) == 0:
        s.append(note("no motion: the partitions, closure residuals and closing joints' "
                      "reactions along it are not available"))
    else:
        parts = res.constraints.partitions
        s.append("<h3>Partitions along the motion</h3>" + html_table(
            [(numstr(t), esc(", ".join(n))) for t, n in parts],
            ["from t / s", "independent coordinates"], "info"))
        max_phi, max_phid = res.closure_residual
        s.append(f"<h3>Closure residuals</h3><p>max|Φ| = {max_phi:.3e}, max|Φ̇| = "
                 f"{max_phid:.3e} over the motion.</p>")
        with np.errstate(divide="ignore"):
            aphi = np.max(np.abs(res.Phi), axis=1) if res.Phi.shape[1] else np.zeros(len(res.t))
            aphid = (np.max(np.abs(res.Phi_dot), axis=1) if res.Phi_dot.shape[1]
                     else np.zeros(len(res.t)))
        floor = 1e-18  # an exact zero drawn at the floor of the logarithmic axis
        s.append(run.figures.add(time_plot, res.t,
                                 {"max |Φ|": np.log10(np.maximum(aphi, floor)),
                                  "max |Φ̇|": np.log10(np.maximum(aphid, floor))},
                                 "log₁₀ residual", "closure residuals along the motion"))
        info.summary_lines.append(f"  closure residuals max|Φ| = {max_phi:.1e}, "
                                  f"max|Φ̇| = {max_phid:.1e}")
        doc.update({"max_Phi": max_phi, "max_Phi_dot": max_phid,
                    "partitions": [[t, list(n)] for t, n in parts],
                    "status": res.status, "message": res.message})
        lam = res.multipliers
        labels = list(res.constraint_labels)
        cols = ["t", *[f"Phi[{r}]" for r in labels], *[f"Phi_d[{r}]" for r in labels],
                *[f"lambda[{r}]" for r in labels]]
        fn_csv = out / "loops.csv"
        np.savetxt(fn_csv, np.column_stack([res.t, res.Phi, res.Phi_dot, lam]),
                   delimiter=",", header=",".join(cols), comments="", fmt="%.17g")
        info.files.append(fn_csv)
        s.append("<p class='meta'>The residuals Φ, Φ̇ and the multipliers λ of every "
                 "constraint row at every sample: loops.csv.</p>")
        if lam.shape[1]:
            s.append(run.figures.add(time_plot, res.t,
                                     {r: lam[:, i]
                                      for i, r in enumerate(labels[:12])},
                                     "λ", "closing joints' multipliers λ along the motion"))
        s.append(closing_wrenches(run, res))
    lin = out / "linearization-equilibrium.json"
    if lin in info.files:  # section 4's eigenvalues, with the loops' numbers
        doc["eigenvalues"] = json.loads(lin.read_text(encoding="utf-8"))["eigenvalues"]
    fn = out / "loops.json"
    fn.write_text(json.dumps(doc, indent=1), encoding="utf-8")
    info.files.append(fn)
    return "".join(s)


def closing_wrenches(run: Run, res: Any) -> str:
    """The closing joints' force and torque along the motion (B on A at A's joint point, in
    A's axes and inertial): a plot of the magnitudes and ``wrench-<closing joint>.csv``."""
    from ...loops.reactions import closing_reactions
    system = run.model.system
    try:
        pv = parameter_vector(system.tree, dict(res.parameters))
        wrenches = closing_reactions(system, res.y, res.multipliers, res.t, pv)
    except (JourdainError, ValueError, KeyError) as exc:
        return note(f"the closing joints' reactions along the motion are not available: {exc}")
    series: dict[str, np.ndarray] = {}
    files = []
    for name, w in wrenches.items():
        series[f"|F| {name}"] = np.linalg.norm(w["F"], axis=1)
        series[f"|T| {name}"] = np.linalg.norm(w["T"], axis=1)
        head = ["t", *[f"{name}.{q}_{c}{suffix}" for suffix in ("", "_inertial")
                       for q in "FT" for c in "xyz"]]
        fn = run.out / f"wrench-{name}.csv"
        np.savetxt(fn, np.column_stack([res.t, w["F"], w["T"], w["F_inertial"],
                                        w["T_inertial"]]),
                   delimiter=",", header=",".join(head), comments="")
        run.info.files.append(fn)
        files.append(fn.name)
    if not series:
        return note("the closing joints have no points (general constraints): their "
                    "reactions are the multipliers λ above")
    return (run.figures.add(time_plot, res.t, dict(list(series.items())[:12]),
                            "force / N, torque / (N·m)",
                            "closing joints' wrenches along the motion (B on A at A's point)")
            + "<p class='meta'>Force and torque vectors per closing joint, in body A's axes "
              f"and in the inertial frame: {esc(', '.join(files))}.</p>")
