"""Section 4 of the report: the linearization about each nominal motion of the model, its
eigenvalues and stability, or its Floquet analysis (``linearization-<name>.json``)."""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from ...errors import JourdainError
from ...workflow import has_capability
from .. import capabilities
from .campbell import campbell_section
from .elastic import mode_views
from .figures import Figures, eigen_plot, multiplier_plot
from .html import SYM, esc, headline_lin, html_table, mathml, matrix_table, note, numstr, snap
from .state import Run


def nominal_placeholder(index: int) -> str:
    """Where the MathML of the model's ``index``-th nominal motion goes in the page."""
    return f"<!--jourdain-nominal-{index}-->"


def linearization_section(run: Run) -> str:
    """Section 4: M̃, P, Q, h (and D, G, K, N, B), eigenvalues and stability about every
    nominal motion, each also in ``linearization-<name>.json``."""
    model, out, info = run.model, run.out, run.info
    system = model.system
    coords = system.coordinate_names
    s = ["<h2>4. Linearization, eigenvalues and stability</h2>",
         f'<div class="eq">{headline_lin()}</div>',
         "<p>M̃·η̈ + P·η̇ + Q·η = h with D = ½(P + Pᵀ) (damping), G = ½(P − Pᵀ) (gyroscopic), "
         "K = ½(Q + Qᵀ) (stiffness), N = ½(Q − Qᵀ) (circulatory).</p>"]
    if not has_capability("linearize"):
        s.append(note("the linearization is not available yet in this version of jourdain"))
        info.notes.append("linearization: not available yet")
    elif not model.nominal:
        s.append(note("the model defines no nominal motion ([nominal.<name>] in the model "
                       "file)"))
    else:
        for index, nominal in enumerate(model.nominal):
            s.append(f"<h3>About “{esc(nominal.name)}”</h3>")
            if nominal.description:
                s.append(f"<p>{esc(nominal.description)}</p>")
            # the motion in MathML comes with the symbolic display (filled in at the end)
            s.append(f"<p>Nominal motion: {nominal_placeholder(index)}</p>")
            try:
                res = capabilities.linear_analysis(model, nominal.name, run.params)
            except JourdainError as exc:
                s.append(note(f"could not linearize: {exc}"))
                info.notes.append(f"linearization about {nominal.name}: {exc}")
                continue
            num = res["numbers"]
            keys = ["M_tilde", "P", "Q", "h"]
            if res["time_invariant"]:
                keys += ["D", "G", "K", "N"]
                if res.get("numerically_time_invariant"):
                    s.append("<p class='meta'>t appears in the expressions but cancels: M̃, P, "
                             "Q (and B) take the same values at every time checked, so the "
                             "system is time-invariant.</p>")
            else:
                s.append(note("time-variant linearization ("
                               + ", ".join(res["linearization"].time_dependence)
                               + " depend on t); numbers at t = 0; no D/G/K/N split, no "
                               "eigenvalues"))
            for k in keys:
                v = np.asarray(num[k], float)
                s.append(f"<h4>{mathml(SYM[k], False)}</h4>"
                         + matrix_table(v, coords, coords if v.ndim == 2 else None))
            if system.inputs and "B" in num:
                s.append(f"<h4>{mathml(SYM['B'], False)}</h4>"
                         + matrix_table(num["B"], coords, system.input_names))
            if res["conservative"] is not None:
                verdict = ("<span class='ok'>conservative</span> (D = 0, N = 0, h = 0)"
                           if res["conservative"] else
                           "<span class='bad'>not conservative</span>: "
                           + ", ".join(n for n in ("D", "N") if np.abs(num[n]).max() > 1e-9
                                       * max(1.0, float(np.abs(num["Q"]).max())))
                           + (" , h ≠ 0" if not res["nominal_check"].is_solution else ""))
                s.append(f"<p>{verdict}</p>")
            elif not res["nominal_check"].is_solution:
                # h against the forces at work at the nominal state, not an absolute number
                s.append(f"<p>h ≠ 0 (largest |h| = {numstr(res['h_norm'])}): the nominal motion "
                         "does not solve the equations of motion.</p>")
            m, st = res["modes"], res["stability"]
            if m is not None:
                rows = []
                lams = snap(m.eigenvalues, 1e-9)
                zetas = snap(m.damping_ratios, 1e-9)
                for lam, fn, z in zip(lams, m.frequencies_hz, zetas, strict=True):
                    rows.append((numstr(lam.real), numstr(lam.imag), numstr(fn), numstr(z)))
                s.append(html_table(rows, ["Re λ / (1/s)", "Im λ / (rad/s)", "f<sub>n</sub> / Hz",
                                       "ζ"]))
                s.append(run.figures.add(eigen_plot, lams, f"eigenvalues about {nominal.name}"))
                if res["time_invariant"]:  # elastic bodies: the lowest modes in 3-D
                    try:
                        s.append(mode_views(run, nominal.name, res["linearization"], m))
                    except JourdainError as exc:
                        s.append(note(f"the modes' 3-D views not available: {exc}"))
            if res.get("cyclic"):
                s.append(f"<p>{esc(capabilities.cyclic_text(res['cyclic']))}.</p>")
            fl = res.get("floquet")
            if fl is not None:
                s.append(floquet_html(fl, nominal.name, run.figures))
                info.summary_lines.append(f"  about {nominal.name} (Floquet, T = "
                                          f"{fl.period:.6g}): {fl.verdict}")
            if st is not None:
                cls = "ok" if st.is_stable else "bad"
                s.append(f"<p>Stability: <span class='{cls}'>{esc(st.verdict)}</span> — "
                         f"{esc(st.reason)}</p>")
                info.summary_lines.append(f"  about {nominal.name}: {st.verdict}")
            if m is not None and res["time_invariant"]:  # a rotor's speed: its Campbell diagram
                s.append(campbell_section(run, nominal.name, res["linearization"]))
            lj = capabilities.jsonable(res)
            fn_ = out / f"linearization-{nominal.name}.json"
            fn_.write_text(json.dumps(lj, indent=1), encoding="utf-8")
            info.files.append(fn_)
    return "".join(s)


def floquet_html(fl: Any, name: str, figures: Figures | None = None) -> str:
    """The Floquet analysis of a periodic nominal motion: multipliers, exponents, the
    plot against the unit circle (drawn by ``figures``, else here) and the verdict."""
    own = figures is None  # a page of its own: the plot put in place here
    figures = Figures() if figures is None else figures
    rows = [(numstr(mu.real), numstr(mu.imag), f"{abs(mu):.8f}",
             numstr(lam.real) if np.isfinite(lam.real) else "−∞", numstr(lam.imag))
            for mu, lam in zip(fl.multipliers, fl.exponents, strict=True)]
    cls = "ok" if fl.is_stable else "bad"
    html = (f"<h4>Floquet analysis (periodic nominal motion, T = {numstr(fl.period)} s)</h4>"
            "<p>Monodromy matrix Φ(t<sub>0</sub> + T, t<sub>0</sub>) of ẋ = A(t)·x over one "
            "period; its eigenvalues are the Floquet multipliers μ, the exponents ln(μ)/T.</p>"
            + html_table(rows, ["Re μ", "Im μ", "|μ|", "Re ln(μ)/T / (1/s)", "Im ln(μ)/T / (rad/s)"])
            + figures.add(multiplier_plot, fl.multipliers, f"Floquet multipliers about {name}")
            + f"<p>Stability (Floquet): <span class='{cls}'>{esc(fl.verdict)}</span> — "
              f"{esc(fl.reason)}</p>")

    return figures.fill(html) if own else html
