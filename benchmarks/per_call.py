"""Per-call cost of the Python API in a user's loop (issue 38, item 7).

A user who loops in Python over parameter values calls ``jd.stability``, ``jd.modes``,
``jd.state_space`` and ``System.linearize`` once per case. Each call should cost what its
numbers cost, not what does not change between calls (the cyclic coordinates of the model, the
graph of the linearization's expressions, the symbolic linearization itself). Measured here,
for each model, as the median of ``--repeat`` calls after one warm-up call (the first call
derives and compiles; it is timed apart):

- ``linearize``: ``system.linearize(nominal)`` (a new ``Linearization`` object each call);
- ``evaluate``: ``lin.evaluate(parameters=...)``;
- ``state_space``: ``jd.state_space(lin, parameters=...)`` (with its nominal check);
- ``modes``: ``jd.modes(lin, parameters=...)``;
- ``stability``: ``jd.stability(lin, parameters=...)`` (cyclic coordinates found by default);
- ``stability_fresh``: the same on a new ``Linearization`` each call
  (``system.linearize`` included), the loop of a user who linearizes per case.

Each call gets another parameter value, so nothing is a cached number of the same call.
Models: the 2-DOF rotor with internal damping (``examples/rotor_internal_damping.toml``,
about its ``centred`` equilibrium) and the precessing top (``examples/precessing_top.toml``,
a regular precession: two cyclic coordinates, a time-variant nominal motion).

    .venv/bin/python benchmarks/per_call.py
    .venv/bin/python benchmarks/per_call.py --repeat 200 --json per_call.json
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _median_ms(fn: Callable[[int], object], repeat: int) -> float:
    times = []
    for i in range(repeat):
        t0 = time.perf_counter()
        fn(i)
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times)


def cases() -> list[tuple[str, object, dict, str, float]]:
    """(name, system, nominal, parameter varied, its default value)."""
    import jourdain as jd

    out = []
    for name, file, p in (("rotor (f = 2)", "rotor_internal_damping.toml", "Omega"),
                          ("precessing top (f = 3)", "precessing_top.toml", "Op")):
        model = jd.load_model(ROOT / "examples" / file)
        nominal = model.nominal_motion()
        y = dict(zip(model.system.coordinate_names, nominal.y, strict=True))
        out.append((name, model.system, y, p, model.system.parameter_values[p]))
    return out


def measure_one(system: object, nominal: dict, p: str, p0: float, repeat: int
                ) -> dict[str, object]:
    """The first call and the medians of the calls of one model."""
    import jourdain as jd

    t0 = time.perf_counter()
    lin = system.linearize(nominal)  # type: ignore[attr-defined]
    jd.stability(lin)
    first = time.perf_counter() - t0

    def pars(i: int) -> dict[str, float]:
        return {p: p0 * (1.0 + 1e-6 * i)}  # a new value at every call

    def fresh(i: int) -> object:
        return jd.stability(system.linearize(nominal), parameters=pars(i))  # type: ignore[attr-defined]

    calls: dict[str, Callable[[int], object]] = {
        "linearize": lambda i: system.linearize(nominal),  # type: ignore[attr-defined]
        "evaluate": lambda i: lin.evaluate(parameters=pars(i)),
        "state_space": lambda i: jd.state_space(lin, parameters=pars(i)),
        "modes": lambda i: jd.modes(lin, parameters=pars(i)),
        "stability": lambda i: jd.stability(lin, parameters=pars(i)),
        "stability_fresh": fresh,
    }
    return {"first_ms": 1e3 * first,
            "ms": {name: _median_ms(fn, repeat) for name, fn in calls.items()}}


def measure(repeat: int) -> list[dict[str, object]]:
    import jourdain as jd

    warnings.simplefilter("ignore", jd.NominalMotionWarning)
    return [{"model": name, **measure_one(system, nominal, p, p0, repeat)}
            for name, system, nominal, p, p0 in cases()]


def main(argv: list[str] | None = None) -> list[dict[str, object]]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=100)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    rows = measure(args.repeat)
    keys = list(rows[0]["ms"])  # type: ignore[arg-type]
    print(f"median of {args.repeat} calls, ms per call (first call: derivation and compilation)")
    print("| model | first | " + " | ".join(keys) + " |")
    print("| --- | --- | " + " | ".join("---" for _ in keys) + " |")
    for r in rows:
        ms = r["ms"]
        print(f"| {r['model']} | {r['first_ms']:.0f} | "
              + " | ".join(f"{ms[k]:.3f}" for k in keys) + " |")  # type: ignore[index]
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return rows


if __name__ == "__main__":
    main()
