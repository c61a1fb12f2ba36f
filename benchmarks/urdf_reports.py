"""``jourdain run`` on URDF robots (issue 13: a report in at most 2 s), and the URDF-specific
parts of it side by side with what they replaced.

For each robot, best of ``--repeat`` runs:

* the wall time of ``jourdain run ROBOT.urdf --out DIR`` in a fresh process, with an empty
  cache folder (compilation and mesh parsing included) and again with the cache it left;
* the parts in this process: importing yourdfpy (with trimesh, which it imports), load_urdf,
  reading the meshes of the 3-D view parsed (first read) against from the store
  (:mod:`jourdain.io.viewer.mesh_store`), and the linearization numbers at one state of
  ``jourdain eval`` / the report: symbolic (System.linearize + evaluate, as before) against
  forward-mode in floating point (linearize_numeric, now), each the first call in the
  process (the symbolic one is memoized after it), printed as a ratio.

    python benchmarks/urdf_reports.py                    # UR5, Solo, examples/planar_arm.urdf
    python benchmarks/urdf_reports.py --robots ur5 --repeat 3

Needs example-robot-data and yourdfpy (the test extra). The machine's load shows in every
number: compare within one run.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "solo": "solo_description/robots/solo.urdf",
    "planar_arm": None,  # examples/planar_arm.urdf
}


def robot_path(name: str) -> Path:
    if ROBOTS[name] is None:
        return ROOT / "examples" / f"{name}.urdf"
    import site

    for base in site.getsitepackages():
        d = Path(base) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if d.is_dir():
            return d / str(ROBOTS[name])
    raise SystemExit("example-robot-data's robots folder not found: pip install example-robot-data")


def run_report(path: Path, cache: Path, out: Path) -> float:
    env = {**os.environ, "JOURDAIN_CACHE": str(cache)}
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "jourdain.cli", "run", str(path), "--out",
                           str(out), "--force"], env=env, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"jourdain run {path} failed:\n{proc.stderr[-2000:]}")
    return dt


def lin_worker_time(kind: str, path: Path, cache: Path) -> float:
    env = {**os.environ, "JOURDAIN_CACHE": str(cache)}
    proc = subprocess.run([sys.executable, __file__, "--worker", kind, str(path)], env=env,
                          capture_output=True, text=True, check=True)
    return float(proc.stdout.split()[-1])


def worker(kind: str, path: str) -> None:
    """Time the linearization numbers at one state after the equations of motion."""
    from jourdain.io import capabilities
    from jourdain.io.urdf import load_urdf
    from jourdain.stages.linearization import NominalMotionWarning

    model = load_urdf(path)
    s = model.system
    rng = np.random.default_rng(7)
    y, yd = rng.uniform(-1, 1, s.f), rng.uniform(-1, 1, s.f)
    s.equations_of_motion()
    t = time.perf_counter()
    if kind == "symbolic":  # as before: System.linearize, then its evaluate
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NominalMotionWarning)
            lin = s.linearize(capabilities.state_nominal(s, y, yd, 0.0, {}))
        lin.evaluate(t=0.0)
    else:  # now: capabilities.linearization_at (linearize_numeric)
        capabilities.linearization_at(model, y, yd, 0.0, {}, {})
    print(time.perf_counter() - t)


def best(fn, repeat: int) -> float:
    return min(fn() for _ in range(repeat))


def bench_robot(name: str, repeat: int) -> str:
    """One row of the table."""
    from jourdain.io.urdf import load_urdf
    from jourdain.io.viewer import mesh_store, meshes

    path = robot_path(name)
    with tempfile.TemporaryDirectory() as tmp:
        cache, out = Path(tmp) / "cache", Path(tmp) / "report"

        def cold() -> float:
            import shutil

            shutil.rmtree(cache, ignore_errors=True)
            return run_report(path, cache, out)

        t_cold = best(cold, repeat)
        t_warm = best(lambda: run_report(path, cache, out), repeat)

        def load() -> float:
            t = time.perf_counter()
            load_urdf(path)
            return time.perf_counter() - t

        t_load = best(load, repeat)
        model = load_urdf(path)
        files = [g.path for g in model.visual_geometry if g.kind == "mesh" and g.path]
        os.environ["JOURDAIN_CACHE"] = str(cache)

        def parsed() -> float:
            mesh_store._memory.clear()
            for f in {mesh_store.digest(Path(p).read_bytes(), Path(p).suffix.lower())
                      for p in files}:
                (cache / "meshes" / f"{f}.npz").unlink(missing_ok=True)
            t = time.perf_counter()
            for p in files:
                meshes.read_mesh(p)
            return time.perf_counter() - t

        def stored() -> float:
            mesh_store._memory.clear()
            t = time.perf_counter()
            for p in files:
                meshes.read_mesh(p)
            return time.perf_counter() - t

        t_parse, t_store = best(parsed, repeat), best(stored, repeat)
        f = model.system.f
        # each in a fresh process after the equations of motion (both need them; the
        # symbolic linearization is memoized within a process)
        t_sym = best(lambda: lin_worker_time("symbolic", path, cache), repeat)
        t_num = best(lambda: lin_worker_time("numeric", path, cache), repeat)
    ratio_m = f"{t_parse / t_store:5.1f}×" if files and t_store > 0 else "     —"
    return (f"{name:<11} {f:>2} {t_cold:>15.2f} s {t_warm:>14.2f} s {t_load:>8.3f} s "
          f"{t_parse:>12.3f} s {t_store:>9.3f} s {ratio_m} {t_sym:>12.3f} s "
          f"{t_num:>6.3f} s {t_sym / t_num:5.1f}×")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robots", nargs="+", default=list(ROBOTS), choices=list(ROBOTS))
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(*args.worker)
        return

    import jourdain.io.report  # noqa: F401 - loaded first, as by jourdain run

    t0 = time.perf_counter()
    import yourdfpy  # noqa: F401 - timed: it imports trimesh

    t_import = time.perf_counter() - t0

    print(f"import yourdfpy (and trimesh) after jourdain: {t_import:.3f} s (once per process)")
    print(f"{'robot':<11} {'f':>2} {'run, empty cache':>17} {'run, warm cache':>16} "
          f"{'load_urdf':>10} {'meshes parsed':>14} {'from store':>11} {'ratio':>6} "
          f"{'lin. symbolic':>14} {'numeric':>8} {'ratio':>6}")
    for name in args.robots:
        print(bench_robot(name, args.repeat), flush=True)


if __name__ == "__main__":
    main()
