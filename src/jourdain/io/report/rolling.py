"""The report of a general system (velocity constraints: rolling contact, ``docs/rolling.md``):
the same sections as a tree's, with the general system's numbers, plus section 6, "Contacts".

* section 2 says why the symbolic equations are not shown (``ẏ = L·z + l`` exists in numbers);
* section 3: M, k, q in the speeds z, the velocity map L and the contact forces at the model's
  initial state (:meth:`jourdain.System.evaluate`);
* section 4: the linearization about each steady motion of the file (its M̃, D, G, K, N,
  eigenvalues and verdict) and, where a parameter appears in the steady motion only (a speed),
  the eigenvalues over that parameter from 0 to twice its value with the stable range found
  by :func:`jourdain.stability_boundary` (``stability-<nominal>.csv``);
* section 5: the simulation section of trees (:meth:`jourdain.System.simulate` in ``(y_i, z)``);
* section 6: the contacts, their rows, the residuals along the motion and the contact forces
  (``contacts.csv``).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

import numpy as np
import symengine as se

from ...analysis.modes import UNSTABLE, stability
from ...analysis.sweep import stability_boundary, sweep
from ...errors import JourdainError
from ...model.validation import force_expressions
from ..capabilities import steady_mapping
from .figures import eigen_plot, plot_axes, svg, time_plot
from .html import SYM, esc, html_table, mathml, matrix_table, note, numstr, snap
from .state import Run

EQUATIONS_HEADING = "<h2>2. Newton–Euler equations and equations of motion</h2>"
#: points of the sweep over a speed-like parameter
SWEEP_POINTS = 101


def contact_names(system: Any) -> str:
    return ", ".join(c.name for c in system.contacts)


def equations_section(run: Run) -> str:
    system = run.model.system
    run.info.notes.append("equations: not available for a general system (numbers only)")
    return (EQUATIONS_HEADING
            + note(f"the symbolic equations are not shown: {system.name!r} is constrained by "
                   f"the contacts {contact_names(system)}, and its equations in the speeds z "
                   "need the velocity map ẏ = L·z + l, which exists in numbers (W = [Y; A] "
                   "solved at a state); sections 3 and 4 give them in numbers, section 6 the "
                   "contacts"))


def _initial(run: Run) -> tuple[np.ndarray, np.ndarray]:
    sim, f = run.model.simulation, run.model.system.f
    return (np.array(sim.y0 or [0.0] * f, float), np.array(sim.yd0 or [0.0] * f, float))


def numbers_section(run: Run) -> str:
    system = run.model.system
    s = ["<h2>3. Numbers at the initial state</h2>"]
    y0, yd0 = _initial(run)
    try:
        out = system.evaluate(y0, yd0, parameters=run.params or None)
    except JourdainError as exc:
        run.info.notes.append(f"numbers: {exc}")
        return "".join(s) + note(f"not available: {exc}")
    coords, z = system.coordinate_names, out["speeds"]
    s.append("<p>" + ", ".join(f"{esc(c)} = {numstr(v)}" for c, v in
                               zip(coords, out["y"], strict=True))
             + f"; speeds z = ({esc(', '.join(z))}) = "
             + ", ".join(numstr(v) for v in out["z"]) + ". M = LᵀM_tree·L, k = Lᵀ(k_tree + "
             "M_tree·γ), q = Lᵀq_tree with ẏ = L·z + l.</p>")
    for k in ("M", "k", "q"):
        s.append(f"<h3>{mathml(SYM[k], False)}</h3>"
                 + matrix_table(out[k], z, z if k == "M" else None))
    s.append("<h3>Velocity map L (ẏ = L·z + l)</h3>" + matrix_table(out["L"], coords, z))
    s.append("<h3>Contact forces</h3>" + html_table(
        [(esc(k), numstr(v)) for k, v in out["contact_forces"].items()],
        ["row", "force / N (along the row's direction, on the body)"], "info"))
    (run.out / "values.json").write_text(json.dumps(
        {k: np.asarray(out[k]).tolist() for k in ("y", "yd", "z", "M", "k", "q", "L")}
        | {"speeds": z, "contact_forces": out["contact_forces"]}, indent=1), encoding="utf-8")
    run.info.files.append(run.out / "values.json")
    return "".join(s)


def _names(exprs: Any) -> set[str]:
    return {str(x) for e in exprs for x in se.sympify(e).free_symbols}


def sweep_parameter(system: Any, nominal: Any) -> str | None:
    """The parameter that the steady motion uses and the model does not (a speed), if one."""
    used = _names([*nominal.y, *nominal.yd])
    kin = system.tree.kinematics()
    model = _names([e for bk in kin.bodies for m in (bk.r_O, bk.S, bk.r) for e in m.entries()])
    for b in system.bodies:
        model |= _names([b.mass, *b.com, *(v for r in b.inertia for v in r)])
    for f in system.forces:
        model |= _names(force_expressions(f))
    for c in system.contacts:
        model |= c.symbols()
    only = sorted(n for n in used & set(system.parameter_values) if n not in model)
    return only[0] if len(only) == 1 else None


def sweep_plot(values: np.ndarray, real: np.ndarray, name: str, bounds: list[float],
               title: str) -> str:
    fig, ax = plot_axes(7.5, 3.4)
    ax.axhline(0, color="0.5", linewidth=0.8)
    ax.plot(values, real, ".", markersize=2.5, color="C0")
    for b in bounds:
        ax.axvline(b, color="C2", linewidth=1.0, linestyle="--")
    ax.set_ylim(max(float(np.nanmin(real)), -20.0), float(np.nanmax(real)) + 1.0)
    ax.set_xlabel(name)
    ax.set_ylabel("Re λ / (1/s)")
    ax.set_title(title)
    return svg(fig)


def _stable_range(lin: Any, name: str, values: np.ndarray, verdicts: Sequence[str],
                  parameters: dict[str, float] | None = None) -> list[float]:
    """The boundaries of the stability verdict over ``values``, each to 1e-10 by
    :func:`jourdain.stability_boundary` (the other parameters at ``parameters``, else at
    the linearization's own)."""
    out = []
    for i in range(len(values) - 1):
        if (verdicts[i] == UNSTABLE) != (verdicts[i + 1] == UNSTABLE):
            out.append(stability_boundary(lin, name, float(values[i]), float(values[i + 1]),
                                          parameters=parameters))
    return out


def linearization_section(run: Run) -> str:
    model, info = run.model, run.info
    system = model.system
    s = ["<h2>4. Linearization about steady motions, eigenvalues and stability</h2>",
         "<p>M̃·η̈ + P·η̇ + Q·η = h in the coordinates η whose rates are speeds, cyclic "
         "coordinates left out; D = ½(P + Pᵀ), G = ½(P − Pᵀ), K = ½(Q + Qᵀ), "
         "N = ½(Q − Qᵀ). Velocity constraints alone make D and N nonzero.</p>"]
    if not model.nominal:
        return "".join(s) + note("the model has no [nominal.<name>] steady motion")
    for nom in model.nominal:
        mapping = steady_mapping(system, nom)
        lin: Any
        try:
            lin = system.linearize(mapping)
            if run.params:
                lin = lin.at(run.params)
        except JourdainError as exc:
            s.append(note(f'nominal "{nom.name}": could not linearize: {exc}'))
            info.notes.append(f"linearization {nom.name}: {exc}")
            continue
        names = list(lin.names)
        s.append(f"<h3>About “{esc(nom.name)}”</h3><p>η = ({esc(', '.join(names))}); cyclic, "
                 f"left out: {esc(', '.join(lin.cyclic) or 'none')}</p>")
        for k in ("M_tilde", "D", "G", "K", "N"):
            s.append(f"<h4>{mathml(SYM[k], False)}</h4>"
                     + matrix_table(np.asarray(getattr(lin, k)), names, names))
        lams = snap(np.asarray(lin.eigenvalues, complex), 1e-9)
        s.append(html_table([(numstr(v.real), numstr(v.imag)) for v in lams],
                            ["Re λ / (1/s)", "Im λ / (rad/s)"]))
        s.append(run.figures.add(eigen_plot, lams, f"eigenvalues about {nom.name}"))
        st = stability(lin)
        s.append(f"<p>Stability: <span class='{'ok' if st.is_stable else 'bad'}'>"
                 f"{esc(st.verdict)}</span> — {esc(st.reason)}</p>")
        info.summary_lines.append(f"  linearized about {nom.name}: {st.verdict}")
        s.append(_sweep(run, nom, lin))
    return "".join(s)


def _sweep(run: Run, nom: Any, lin: Any) -> str:
    system = run.model.system
    name = sweep_parameter(system, nom)
    if name is None:
        return ""
    top = 2.0 * float(lin.parameters[name]) or 1.0
    values = np.linspace(0.0, top, SWEEP_POINTS)
    try:  # η may lose a decoupled cyclic speed at some values (a disc not spinning): NaN
        sw = sweep(lin, name, values)
    except JourdainError as exc:
        run.info.notes.append(f"{nom.name} over {name}: {exc}")
        return note(f"the eigenvalues over {name} are not available: {exc}")
    lam, verdicts = sw.eigenvalues, sw.verdicts
    n = lam.shape[1]
    real = list(lam.real)
    try:
        bounds = _stable_range(lin, name, values, verdicts)
    except JourdainError as exc:
        run.info.notes.append(f"{nom.name}: stability boundary over {name}: {exc}")
        bounds = []
    fn = run.out / f"stability-{nom.name}.csv"
    head = ",".join([name, *(f"re{i}" for i in range(n)), *(f"im{i}" for i in range(n))])
    np.savetxt(fn, np.column_stack([values, lam.real, lam.imag]), delimiter=",", header=head,
               comments="")
    run.info.files.append(fn)
    xs = np.repeat(values, n)
    fig = run.figures.add(sweep_plot, xs, np.concatenate(real), name, bounds,
                          f"eigenvalues over {name} about {nom.name}")
    stable = [(a, b) for a, b in zip([0.0, *bounds], [*bounds, top], strict=True)
              if verdicts[int(np.searchsorted(values, 0.5 * (a + b)))] != UNSTABLE]
    text = ("; ".join(f"{a:.4f} – {b:.4f}" for a, b in stable) if stable else "none")
    run.info.summary_lines.append(f"  stable {name} range about {nom.name}: {text}")
    return (f"<h4>Over {esc(name)} (0 … {numstr(top)})</h4>" + fig
            + f"<p>Stable for {esc(name)} in: <b>{esc(text)}</b> (boundaries "
            + ", ".join(f"{b:.10g}" for b in bounds) + " by jourdain.stability_boundary).</p>")


def contacts_section(run: Run, res: Any) -> str:
    system = run.model.system
    s = ["<h2>6. Contacts</h2>", html_table(
        [(esc(c.name), esc(type(c).__name__), esc(", ".join(c.bodies))) for c in system.contacts],
        ["contact", "type", "body"], "info")]
    if res is None or res.constraints is None or not len(res.t):
        return "".join(s) + note("no motion to show")
    c = res.constraints
    s.append(f"<p>Residuals along the motion: max |Φ| = {numstr(np.abs(c.Phi).max())}, "
             f"max |A·ẏ + a| = {numstr(np.abs(c.Phi_dot).max())}.</p>")
    series = {lab: c.multipliers[:, i] for i, lab in enumerate(c.labels)}
    s.append(run.figures.add(time_plot, res.t, series, "force / N", "contact forces"))
    fn = run.out / "contacts.csv"
    np.savetxt(fn, np.column_stack([res.t, c.multipliers, c.Phi, c.Phi_dot]), delimiter=",",
               header=",".join(["t", *c.labels, *(f"Phi.{n}" for n in c.labels),
                                *(f"Phi_dot.{n}" for n in c.labels)]), comments="")
    run.info.files.append(fn)
    return "".join(s)


__all__ = ["contacts_section", "equations_section", "linearization_section",
           "numbers_section", "sweep_parameter"]
