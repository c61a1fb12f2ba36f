"""FMUs of URDF robots from example-robot-data, run in FMPy against jourdain's own simulation.

For each robot: load_urdf, export_fmu with every reaction component as an output, FMPy's
validate_fmu, then FMPy in model exchange (CVode) and co-simulation (the FMU's Dormand–Prince
5(4)) from a random pose at rest with zero joint torques, against System.simulate (DOP853 at
rtol 1e-11), and the reaction outputs at the FMU's final state against System.evaluate. Prints
the largest differences of y and ẏ (absolute, and relative to the largest |state|).

    python benchmarks/fmu.py                      # UR5 (6 joints), Panda (7 + 2 fingers), Solo-12
    python benchmarks/fmu.py --robots ur5 --t-end 2 --rtol 1e-12

Needs the test extra (FMPy, example-robot-data, yourdfpy). Not part of make test (compiles
three FMUs and simulates each three times: about a minute on two cores).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", {}),
    "panda": ("panda_description/urdf/panda.urdf", {"mimic": "independent"}),
    "solo12": ("solo_description/robots/solo12.urdf", {"floating_base": True}),
}


def robots_dir() -> Path:
    """The robots of the example-robot-data wheel (a cmeel package: files, no module)."""
    import site

    for base in site.getsitepackages():
        d = Path(base) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if d.is_dir():
            return d
    raise SystemExit("example-robot-data's robots folder not found: pip install example-robot-data")


def run(name: str, t_end: float, rtol: float, out: Path) -> None:
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu

    from jourdain.io.fmu import export_fmu
    from jourdain.io.urdf import load_urdf

    rel, kw = ROBOTS[name]
    t0 = time.perf_counter()
    model = load_urdf(str(robots_dir() / rel), **kw)
    s = model.system
    info = export_fmu(model, out / f"{name}.fmu", reactions="all")
    t_export = time.perf_counter() - t0
    problems = validate_fmu(str(info.path))
    rng = np.random.default_rng(1)
    y0 = rng.uniform(-0.5, 0.5, s.f)
    u = {n: 0.0 for n in s.input_names}
    t = np.linspace(0.0, t_end, 101)
    ref = s.simulate((0.0, t_end), y0, np.zeros(s.f), inputs=u or None, rtol=1e-11,
                     atol=1e-13, t_eval=t)
    expected = np.column_stack([ref.y, ref.yd])
    names = s.coordinate_names + [c + "_d" for c in s.coordinate_names]
    print(f"{name}: f = {s.f}, {len(s.bodies)} bodies, {len(info.reactions)} reaction outputs; "
          f"load + export {t_export:.1f} s; validate_fmu: {problems or 'no problems'}")
    for fmi_type, extra in (("ModelExchange", {"solver": "CVode"}), ("CoSimulation", {})):
        t1 = time.perf_counter()
        r = simulate_fmu(str(info.path), fmi_type=fmi_type, stop_time=t_end,
                         output_interval=t_end / 100, relative_tolerance=rtol,
                         start_values=dict(zip(s.coordinate_names, y0, strict=True)),
                         output=names + list(info.reactions), **extra)
        got = np.column_stack([r[n] for n in names])
        err = np.abs(got - expected).max()
        yf, ydf = got[-1, :s.f], got[-1, s.f:]
        ev = s.evaluate(yf, ydf, t=float(r["time"][-1]), inputs=u or None)
        g_err = max(abs(r[g][-1] - v) for g, v in zip(ev["g_names"], ev["g"], strict=True))
        g_scale = float(np.abs(ev["g"]).max())
        print(f"  {fmi_type:14s} {time.perf_counter() - t1:5.2f} s: max |Δ(y, ẏ)| = {err:.2e} "
              f"({err / np.abs(expected).max():.1e} of max |state| {np.abs(expected).max():.3g});"
              f" reactions at the end: max |Δg| = {g_err:.1e} of {g_scale:.3g}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robots", nargs="+", default=list(ROBOTS), choices=list(ROBOTS))
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--rtol", type=float, default=1e-10, help="FMPy's relative tolerance")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.robots:
            run(name, args.t_end, args.rtol, Path(tmp))


if __name__ == "__main__":
    main()
