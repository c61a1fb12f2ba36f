"""``jourdain run`` time per example (issue 13: at most 2 s each, every example).

Each example of ``examples/`` (every ``.toml`` and ``.urdf``; none excluded) is reported by
``jourdain run EXAMPLE --out DIR --force`` in a fresh Python process, timed from the start of
the process to its exit (imports included), in three states of the compile cache:

- **empty**: a new, empty ``JOURDAIN_CACHE`` for each repetition (C code generated and
  compiled, the report's symbolic display computed), the integrator library as the install
  compiled it (``setup.py``: a machine's first run after ``pip install``; the script says
  whether the install did) — also what a user sees after every change to the model;
- **nothing prebuilt**: the same, with ``JOURDAIN_PREBUILT`` empty: the integrator library
  compiled by the run too (an install that had no compiler; a checkout whose integrator source
  changed since it was installed);
- **warm**: the first state's cache after that run (what a user sees the second time; the
  compiled libraries and the display are read from the cache).

Reported per example: the best of ``--repeat`` runs in each state (the machine is shared: the
best is the least disturbed), its exit status, the ratio of the warm time to the 2 s target
and the processor time (user + system, the process and its workers) of the warm run, which
a loaded machine inflates much less than the wall time; then the worst example of each
state. Before the timings, one untimed run writes the
bytecode of every module imported (a fresh checkout's first run compiles them; the runs are
made without ``PYTHONDONTWRITEBYTECODE``, which some sandboxes set). The floor of
every run, ``python -c "import jourdain.cli"``, is timed the same way and printed first.

``--compare``: besides, for each example and the warm cache, the way reports were made before
the workers and the display cache (everything in the command's process, the symbolic display
computed each time: ``write_report(parallel=False)`` with the cache bypassed), in a fresh
process too, and the ratio of its time to ``jourdain run``'s, both measured in turn in one run.

Usage::

    python benchmarks/report.py                       # every example, 3 repetitions
    python benchmarks/report.py --repeat 1 --only double_pendulum robot_arm
    python benchmarks/report.py --json times.json
    python benchmarks/report.py --compare --only robot_arm
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: issue 13: seconds per example
TARGET_SECONDS = 2.0


#: where the integrator library of a run with an empty cache comes from (printed first)
WHERE_INTEGRATOR = ("from jourdain.simulation.problem import integrator_library; "
                    "print(integrator_library()._name)")


def examples(only: list[str] | None) -> list[Path]:
    """Every model file of ``examples/`` (``--only``: those whose stem is named)."""
    found = sorted(p for p in EXAMPLES.iterdir() if p.suffix in (".toml", ".urdf"))
    if only:
        missing = set(only) - {p.stem for p in found}
        if missing:
            raise SystemExit(f"--only: no example {', '.join(sorted(missing))} in {EXAMPLES}")
        found = [p for p in found if p.stem in only]
    return found


def timed(cmd: list[str], cache: Path, prebuilt: bool = True) -> tuple[float, int, str, float]:
    """Seconds from the start of ``cmd`` to its exit, its exit status, its last line of
    error output (the process's own compile cache ``cache``; ``prebuilt``: False, the
    libraries compiled at install time not used) and the processor seconds (user and system)
    of it and its children: on a machine shared with other work the wall time grows with the
    load, the processor time much less."""
    env = {**os.environ, "JOURDAIN_CACHE": str(cache), "PYTHONPATH": str(ROOT / "src")}
    if not prebuilt:
        env["JOURDAIN_PREBUILT"] = ""
    # bytecode as a user's Python writes it: a sandbox's PYTHONDONTWRITEBYTECODE=1 would make
    # every run compile every module of jourdain from source again (0.4-0.8 s a run)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    err = (proc.stderr.strip().splitlines() or [""])[-1]
    return wall, proc.returncode, err, cpu


def run_cmd(model: Path, out: Path) -> list[str]:
    return [sys.executable, "-m", "jourdain.cli", "run", str(model), "--out", str(out),
            "--force"]


#: the report as made before the workers and the display cache (for --compare)
IN_PROCESS = """
import sys
from pathlib import Path
import jourdain as jd
from jourdain.io.report import document, equations
document.cached_display = equations.compute_display  # the display computed every time
path = sys.argv[1]
model = jd.load_urdf(path) if path.endswith(".urdf") else jd.load_model(path)
info = document.write_report(model, Path(sys.argv[2]), parallel=False)
sys.exit(0 if info.status == "complete" else 1)
"""


def compare(model: Path, base: Path, repeat: int) -> tuple[float, float, int]:
    """Best seconds of the in-process report without the display cache and of ``jourdain
    run``, timed in turn, the compile cache warm; the first nonzero exit status (else 0)."""
    cache = base / f"compare-{model.stem}"
    timed(run_cmd(model, base / "c0"), cache)  # compiled once, untimed
    before, after, codes = [], [], []
    for _ in range(repeat):
        wall, rc, _, _ = timed([sys.executable, "-c", IN_PROCESS, str(model),
                                str(base / "c1")], cache)
        before.append(wall)
        codes.append(rc)
        wall, rc, _, _ = timed(run_cmd(model, base / "c2"), cache)
        after.append(wall)
        codes.append(rc)
    return min(before), min(after), next((c for c in codes if c), 0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs per example and state")
    ap.add_argument("--only", nargs="*", help="example names (file stems)")
    ap.add_argument("--json", help="write the times to this file")
    ap.add_argument("--compare", action="store_true",
                    help="also time the in-process report without the display cache")
    args = ap.parse_args()
    models = examples(args.only)
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory(prefix="jd-bench-report-") as tmp:
        base = Path(tmp)
        # bytecode of every module a run imports, written once, untimed
        timed(run_cmd(models[0], base / "warmup"), base / "warmup-cache")
        floor = min(timed([sys.executable, "-c", "import jourdain.cli"], base / "c")[0::3]
                    for _ in range(args.repeat))
        print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores; best of "
              f"{args.repeat}; target {TARGET_SECONDS:g} s per example")
        print(f"floor: python -c 'import jourdain.cli': {floor[0]:.2f} s "
              f"(processor {floor[1]:.2f} s)")
        where = subprocess.run([sys.executable, "-c", WHERE_INTEGRATOR], capture_output=True,
                               text=True, env={**os.environ, "PYTHONPATH": str(ROOT / "src"),
                                               "JOURDAIN_CACHE": str(base / "where")})
        so = where.stdout.strip()
        print("integrator library with an empty cache: "
              + (f"compiled at install, {so}" if not so.startswith(str(base))
                 else "not compiled at install (setup.py): the empty-cache runs compile it")
              + "\n")
        print(f"{'example':<28} {'empty cache':>12} {'no prebuilt':>12} {'warm cache':>11} "
              f"{'warm/target':>12} "
              f"{'warm, processor':>16}")
        for k, model in enumerate(models):
            out = base / f"out{k}"
            empty, bare, warm, warm_cpu = [], [], [], []
            status: list[tuple[int, str]] = []
            for r in range(args.repeat):
                wall, rc, err, _ = timed(run_cmd(model, out), base / f"bare{k}-{r}",
                                         prebuilt=False)
                bare.append(wall)
                status.append((rc, err))
                cache = base / f"cache{k}-{r}"
                wall, rc, err, _ = timed(run_cmd(model, out), cache)  # empty cache
                empty.append(wall)
                status.append((rc, err))
                wall, rc, err, cpu = timed(run_cmd(model, out), cache)  # the same, warm
                warm.append(wall)
                warm_cpu.append(cpu)
                status.append((rc, err))
            bad = [(rc, err) for rc, err in status if rc != 0]
            row: dict[str, Any] = {
                "example": model.name, "empty_s": min(empty), "no_prebuilt_s": min(bare),
                "warm_s": min(warm),
                "warm_cpu_s": min(warm_cpu),
                "exit": bad[0][0] if bad else 0, "error": bad[0][1] if bad else ""}
            rows.append(row)
            flag = "" if not bad else f"   exit {bad[0][0]}: {bad[0][1][:60]}"
            print(f"{model.name:<28} {row['empty_s']:>10.2f} s {row['no_prebuilt_s']:>10.2f} s "
                  f"{row['warm_s']:>9.2f} s "
                  f"{row['warm_s'] / TARGET_SECONDS:>11.2f}× {row['warm_cpu_s']:>14.2f} s{flag}",
                  flush=True)
            if args.compare:
                row["in_process_s"], row["run_s"], rc = compare(model, base, args.repeat)
                print(f"{'':<4}in-process, display computed {row['in_process_s']:.2f} s; "
                      f"jourdain run {row['run_s']:.2f} s: "
                      f"{row['in_process_s'] / row['run_s']:.2f}× faster"
                      + (f" (a run exited {rc}: not comparable)" if rc else ""), flush=True)
    worst_empty = max(rows, key=lambda r: r["empty_s"])
    worst_warm = max(rows, key=lambda r: r["warm_s"])
    worst_bare = max(rows, key=lambda r: r["no_prebuilt_s"])
    print(f"\nworst, empty cache: {worst_empty['example']} {worst_empty['empty_s']:.2f} s "
          f"({worst_empty['empty_s'] / TARGET_SECONDS:.2f}× the target)")
    print(f"worst, no prebuilt: {worst_bare['example']} {worst_bare['no_prebuilt_s']:.2f} s "
          f"({worst_bare['no_prebuilt_s'] / TARGET_SECONDS:.2f}× the target)")
    print(f"worst, warm cache:  {worst_warm['example']} {worst_warm['warm_s']:.2f} s "
          f"({worst_warm['warm_s'] / TARGET_SECONDS:.2f}× the target)")
    if args.json:
        Path(args.json).write_text(json.dumps({"floor_s": floor[0], "examples": rows},
                                              indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
