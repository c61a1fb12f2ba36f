"""Parameter studies: a stability map and a Monte-Carlo simulation, against plain Python loops.

1. A stability map of ``examples/rotor_internal_damping.toml`` over the spin rate Omega and the
   internal damping d_i (``--n`` × ``--n`` grid, 100 × 100 = 10 000 cases by default):

   * *loop*: what a user writes today, a Python loop over ``jourdain.analysis.stability`` of
     the linearization (``System.linearize`` once, then per case the symbolic result evaluated
     and judged); timed on ``--loop-cases`` cases, reported as cases per second;
   * *loop, compiled*: the same loop over the compiled linearization (``lin.compile()``);
   * *batched*: :func:`jourdain.study.run_study` in this process (blocks of 512 cases: one C
     call for M̃, P, Q, h of a block, stacked solves and eigenvalues), the derivation and
     compilation not counted (timed apart as *set-up*);
   * *1 → 2 workers*: the whole ``run_study`` call on 1 and 2 threads (``pool="auto"``), on 2
     fresh processes (worker start and model rebuild included) and on warm Dask
     ``LocalCluster``s of 1 and 2 workers, medians of ``--rounds`` interleaved rounds, beside
     the ceiling of the map's own LAPACK work on two threads measured in the same rounds; and
     the same again on a 300 × 300 map (``--scaling-n``), where the work outweighs a run's
     fixed costs (a Dask run's scheduler, messages and results, on the same two cores).

   The batched verdicts are compared with the loop's on the cases the loop ran.

2. A Monte-Carlo run of ``examples/quarter_car.toml`` (``--mc`` runs, 1 000 by default): body
   mass, stiffnesses and damping drawn from normal distributions, 4 s of road excitation each,
   the largest body displacement per run; runs per second of per-case runs (one
   ``simulate()`` each, ``ensemble = false``) against ensembles (a block's runs in one C call,
   :mod:`jourdain.study.ensemble`), on 1 and 2 workers (processes; threads for the ensembles,
   which release the GIL), side by side; the C integration alone, for the share left to it.

    python benchmarks/study.py             # 10 000 cases (and 1 -> 2 workers on 90 000),
                                           # 1 000 runs (about two minutes)
    python benchmarks/study.py --quick     # 40 × 40 cases, 200 runs
    python benchmarks/study.py --only mc   # the Monte-Carlo part alone
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from jourdain.analysis import stability  # noqa: E402
from jourdain.io.capabilities import nominal_mapping  # noqa: E402
from jourdain.study import VERDICTS, loads_study, run_study  # noqa: E402
from jourdain.study.compute import case_arrays, context  # noqa: E402

ROTOR = ROOT / "examples" / "rotor_internal_damping.toml"
CAR = ROOT / "examples" / "quarter_car.toml"


def _map_spec(n: int) -> str:
    return f"""[study]
model = "{ROTOR}"
name = "rotor stability map"
design = "grid"
block = 512
[vary.Omega]
range = {{ start = 0, stop = 40, num = {n} }}
[vary.d_i]
range = {{ start = 0.1, stop = 3.0, num = {n} }}
[compute.linearize]
"""


def _mc_spec(n: int) -> str:
    return f"""[study]
model = "{CAR}"
name = "quarter car Monte-Carlo"
design = "random"
samples = {n}
seed = 1
block = 25
[vary.m_b]
distribution = "normal"
mean = 300
std = 15
[vary.k_s]
distribution = "normal"
mean = 15000
std = 750
[vary.d_s]
distribution = "normal"
mean = 1200
std = 120
[vary.k_t]
distribution = "normal"
mean = 180000
std = 9000
[compute.simulate]
t_end = 4.0
samples = 401
max_abs = ["z_b"]
final = false
"""


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def stability_map(n: int, loop_cases: int, rounds: int = 9) -> dict:
    spec = loads_study(_map_spec(n))
    t_setup, ctx = _timed(lambda: context(spec))
    system, model = ctx.system, ctx.model
    # about the model's first nominal motion, as the study's default: the context's own
    lin, clin = ctx.linearization, ctx.compiled_linearization
    cases = ctx.cases
    rng = np.random.default_rng(0)
    pick = np.sort(rng.choice(len(cases), size=min(loop_cases, len(cases)), replace=False))

    def loop(target: object) -> list[str]:
        return [stability(target, parameters={"Omega": float(c[0]), "d_i": float(c[1])},
                          cyclic=()).verdict for c in cases[pick]]

    t_loop, verdicts_loop = _timed(lambda: loop(lin))
    t_cloop, verdicts_cloop = _timed(lambda: loop(clin))
    nominal = nominal_mapping(system, model.nominal_motion())

    def relinearize() -> list[str]:  # System.linearize for every case, as a script would
        return [stability(system.linearize(nominal), parameters={
            "Omega": float(c[0]), "d_i": float(c[1])}, cyclic=()).verdict
            for c in cases[pick[:5]]]

    t_relin, _ = _timed(relinearize)
    run_study(spec, workers=1, quiet=True)  # imports (xarray) and first calls, not counted
    t_batch, ds = _timed(lambda: run_study(spec, workers=1, quiet=True))
    ours = [VERDICTS[int(v)] for v in ds["verdict"].values.reshape(-1)[pick]]
    agree = sum(a == b for a, b in zip(ours, verdicts_loop, strict=True))
    scaling = _scaling(spec, ctx, ds, rounds)
    N = len(cases)
    out = {
        "cases": N, "setup_s": t_setup,
        "loop_cases_per_s": len(pick) / t_loop,
        "compiled_loop_cases_per_s": len(pick) / t_cloop,
        "relinearize_loop_cases_per_s": 5 / t_relin,
        "batched_cases_per_s": N / t_batch,
        "speedup_vs_relinearize_loop": (N / t_batch) / (5 / t_relin),
        "speedup_vs_loop": (N / t_batch) / (len(pick) / t_loop),
        "speedup_vs_compiled_loop": (N / t_batch) / (len(pick) / t_cloop),
        "verdicts_agree": f"{agree}/{len(pick)}",
        "compiled_loop_agrees": verdicts_cloop == verdicts_loop,
        "unstable_fraction": float(np.mean(ds["verdict"].values == 2)),
        **scaling,
    }
    return out


def map_scaling(n: int, rounds: int) -> dict:
    """1 → 2 workers alone (:func:`_scaling`) on an n × n map: the 10 000-case map runs 70–130
    ms on one worker, to which a Dask run's fixed costs (scheduler, messages, results; on the
    same two cores as its workers) add 12–20 ms; on a larger map the work outweighs them."""
    spec = loads_study(_map_spec(n))
    ctx = context(spec)
    ref = run_study(spec, workers=1, quiet=True)
    return {"cases": len(ctx.cases), **_scaling(spec, ctx, ref, rounds)}


def _scaling(spec: object, ctx: object, ref: object, rounds: int) -> dict:
    """1 against 2 workers, in ``rounds`` interleaved rounds (medians): ``run_study`` on 1
    worker, on 2 (``pool="auto"``: threads, the work releasing the GIL), on 2 fresh processes,
    and on warm Dask LocalClusters of 1 and 2 worker processes (both clusters up, the runs
    interleaved); and in the same rounds what this machine gives two threads for the study's
    own LAPACK work alone (the eigenvalues of the map's state matrices, split in two halves
    that need no GIL; two thirds of the 1-worker study's time): the ceiling to read the
    1 → 2 figures against on a shared machine."""
    from jourdain.study.linear import linearization_numbers, state_matrices

    nums = linearization_numbers(ctx, case_arrays(ctx, 0, len(ctx.cases))[0])
    A, _ = state_matrices(nums["M_tilde"], nums["P"], nums["Q"])
    halves = (A[0::2], A[1::2])

    def eig(stacks: tuple) -> None:
        for a in stacks:
            np.linalg.eigvals(a)

    def eig_two_threads() -> None:
        import threading

        th = [threading.Thread(target=eig, args=((h,),)) for h in halves]
        for t in th:
            t.start()
        for t in th:
            t.join()

    local: dict = {
        "1_worker": lambda: run_study(spec, workers=1, quiet=True),
        "2_workers": lambda: run_study(spec, workers=2, quiet=True),
        "lapack_1_thread": lambda: eig(halves),
        "lapack_2_threads": eig_two_threads,
    }
    times: dict = {}
    identical: dict = {}
    _rounds(local, rounds, ref, times, identical)
    # fresh processes apart too (forking a pool every round disturbed the threads' timings)
    _rounds({"2_processes": lambda: run_study(spec, workers=2, pool="processes", quiet=True)},
            rounds, ref, times, identical)
    # the Dask clusters apart: their idle workers' event loops would disturb the rest
    _dask_rounds(spec, ref, "max_real_part", rounds, times, identical,
                 {"dask_lapack_1_thread": local["lapack_1_thread"],
                  "dask_lapack_2_threads": local["lapack_2_threads"]},
                 fixed=loads_study(_map_spec(2)))
    med = {f"{k}_s": float(np.median(v)) for k, v in times.items()}
    out = {"rounds": rounds, **med, "identical": identical,
           "threads_speedup": med["1_worker_s"] / med["2_workers_s"],
           "processes_speedup": med["1_worker_s"] / med["2_processes_s"],
           "lapack_ceiling": med["lapack_1_thread_s"] / med["lapack_2_threads_s"]}
    if "dask_2_s" in med:
        out["dask_speedup"] = med["dask_1_s"] / med["dask_2_s"]
        out["dask_lapack_ceiling"] = (med["dask_lapack_1_thread_s"]
                                      / med["dask_lapack_2_threads_s"])
    if "dask_fixed_2_s" in med:
        # two free cores: the 1-worker run's work halved, each run's fixed costs kept
        work = med["dask_1_s"] - med["dask_fixed_1_s"]
        out["dask_free_cores_bound"] = med["dask_1_s"] / (work / 2 + med["dask_fixed_2_s"])
    return out


def _rounds(runs: dict, rounds: int, ref: object, times: dict, identical: dict,
            var: str = "max_real_part") -> None:
    """Every run once (first calls: the workers build the model), then ``rounds`` rounds of
    each in turn; the times appended to ``times[name]``; whether a study's ``var`` equals
    ``ref``'s bit for bit in ``identical[name]``."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        for fn in runs.values():
            fn()
        for _ in range(rounds):
            for k, fn in runs.items():
                t, res = _timed(fn)
                times.setdefault(k, []).append(t)
                if hasattr(res, "data_vars"):
                    identical[k] = bool(np.array_equal(res[var].values, ref[var].values,
                                                       equal_nan=True))


def _dask_rounds(spec: object, ref: object, var: str, rounds: int, times: dict,
                 identical: dict, extra: dict | None = None, fixed: object = None) -> None:
    """The study on warm LocalClusters of 1 and of 2 worker processes (one thread each), both
    up, in interleaved rounds with the ``extra`` runs (:func:`_rounds`: times under
    ``dask_1`` and ``dask_2``); then, where given, the ``fixed`` study (a few cases: what a
    run costs beside its work: the scheduler, the messages, the results, the dataset) on
    both, under ``dask_fixed_1`` and ``dask_fixed_2``; nothing without dask.distributed."""
    try:
        import distributed
    except ImportError:
        return
    clusters: list = []
    runs: dict = {}
    try:
        for n in (1, 2):
            with warnings.catch_warnings():
                # the two schedulers' HTTP servers (health routes; no dashboard): the second
                # finds the default port taken and says so
                warnings.filterwarnings("ignore", "Port 8787 is already in use")
                cl = distributed.LocalCluster(n_workers=n, threads_per_worker=1,
                                              processes=True, dashboard_address=None)
            client = distributed.Client(cl)
            clusters.append((cl, client))
            runs[f"dask_{n}"] = lambda client=client: run_study(spec, scheduler=client,
                                                                quiet=True)
        runs.update(extra or {})
        _rounds(runs, rounds, ref, times, identical, var)
        if fixed is not None:  # after the rest: a worker keeps the model of one study
            few = {f"dask_fixed_{n}": lambda client=client: run_study(fixed, scheduler=client,
                                                                      quiet=True)
                   for n, (_, client) in enumerate(clusters, start=1)}
            _rounds(few, rounds, run_study(fixed, workers=1, quiet=True), times, identical,
                    var)
    finally:
        for cl, client in reversed(clusters):  # each client restores the Dask config it found
            client.close()
            cl.close()


def _best(fn, repeat: int):
    """The fastest of ``repeat`` timed calls (the machine is shared: the least disturbed)."""
    return min((_timed(fn) for _ in range(repeat)), key=lambda r: r[0])


def monte_carlo(n: int, repeat: int = 3) -> dict:
    """The quarter-car Monte-Carlo, per-case runs (``ensemble = false``: one
    ``simulate()`` per case) against ensembles (a block's runs in one C call), on 1 and 2
    workers; every variant's numbers compared with the per-case serial run's."""
    from jourdain.study.ensemble import Ensemble

    text = _mc_spec(n)
    ens = loads_study(text)
    per = loads_study(text.replace("final = false", "final = false\nensemble = false"))
    for spec in (ens, per):
        context(spec)
        run_study(loads_study(_mc_spec(4)), workers=1, quiet=True)  # imports, first calls
    variants = {
        "per_case_1": (per, {"workers": 1}),
        "per_case_2_processes": (per, {"workers": 2, "pool": "processes"}),
        "ensemble_1": (ens, {"workers": 1}),
        "ensemble_2_threads": (ens, {"workers": 2, "pool": "threads"}),
        "ensemble_2_processes": (ens, {"workers": 2, "pool": "processes"}),
    }
    out: dict = {"runs": n, "repeat": repeat}
    ref = None
    for name, (spec, kw) in variants.items():
        t, ds = _best(lambda spec=spec, kw=kw: run_study(spec, quiet=True, **kw), repeat)
        z = ds["max_abs_z_b"].values
        if ref is None:
            ref = z
        out[f"{name}_s"] = t
        out[f"{name}_runs_per_s"] = n / t
        out[f"{name}_identical"] = bool(np.array_equal(z, ref, equal_nan=True))
    # the C integration alone: the ensemble's runs of all cases in one call, no study around
    ctx = context(ens)
    P, Y, YD = case_arrays(ctx, 0, n)
    for threads in (1, 2):
        t, _ = _best(lambda threads=threads: ctx.ensemble.run(P, Y, YD, threads=threads),
                     repeat)
        out[f"c_only_{threads}_s"] = t
    # what a lock-step ensemble (one vectorized right-hand side for all cases per stage) could
    # speed up at most: the model's M, k, q, here timed in one C loop over many states, times
    # the number of evaluations the runs made; the rest of the C time is each case's own step
    # loop (stage sums, error norm, step control, dense output), which lock-step keeps
    from jourdain.numeric import mkq_function

    nfev = int(ctx.ensemble.run(P, Y, YD).nfev.sum())
    mkq = mkq_function(ctx.system)
    rng = np.random.default_rng(0)
    # 2 000 states per call (in cache, the output array reused), 50 calls: the C loop's cost
    # per state, the call's own overhead (40 µs) spread over the states
    m, calls, f, n_u = 2000, 50, ctx.system.f, len(ctx.system.inputs)
    Ys, YDs = rng.normal(0, 0.02, (m, f)), rng.normal(0, 0.2, (m, f))
    Ps = P[rng.integers(0, n, m)]
    Us = rng.normal(0, 0.02, (m, n_u)) if n_u else None
    buf = np.empty((m, mkq.size))

    def mkq_calls() -> None:
        for _ in range(calls):
            mkq.batch(Ys, YDs, 1.0, Ps, Us, out=buf)

    t_mkq, _ = _best(mkq_calls, 5 * repeat)
    per_state = t_mkq / (calls * m)
    out.update(nfev_total=nfev, mkq_ns=per_state * 1e9,
               c_ns_per_evaluation=out["c_only_1_s"] / nfev * 1e9,
               mkq_share_of_c=per_state * nfev / out["c_only_1_s"])
    out["ensemble_vs_per_case_1"] = out["per_case_1_s"] / out["ensemble_1_s"]
    out["ensemble_vs_per_case_2"] = out["per_case_2_processes_s"] / out["ensemble_2_threads_s"]
    out["per_case_1_to_2"] = out["per_case_1_s"] / out["per_case_2_processes_s"]
    out["ensemble_1_to_2_threads"] = out["ensemble_1_s"] / out["ensemble_2_threads_s"]
    out["ensemble_1_to_2_processes"] = out["ensemble_1_s"] / out["ensemble_2_processes_s"]
    out["c_share_of_ensemble_1"] = out["c_only_1_s"] / out["ensemble_1_s"]
    times: dict = {}
    identical: dict = {}
    _dask_rounds(ens, run_study(ens, workers=1, quiet=True), "max_abs_z_b", repeat, times,
                 identical)
    if times:
        out.update({f"dask_{n}_workers_s": float(np.median(times[f"dask_{n}"])) for n in (1, 2)})
        out.update({f"dask_{n}_identical": identical[f"dask_{n}"] for n in (1, 2)})
        out["dask_speedup"] = out["dask_1_workers_s"] / out["dask_2_workers_s"]
    z = ref if ref is not None else np.zeros(1)
    out.update(failed=int(np.isnan(z).sum()), max_abs_z_b_mean_mm=float(np.nanmean(z) * 1e3),
               max_abs_z_b_std_mm=float(np.nanstd(z, ddof=1) * 1e3),
               ensemble_supported=Ensemble.supports("DOP853", None))
    return out


def _busy(_: int) -> int:
    s = 0
    for i in range(3_000_000):
        s += i
    return s


def machine_ceiling(rounds: int = 7) -> tuple[float, float, float]:
    """What 2 processes give on this machine now: two units of pure-Python work, one after the
    other against one each on 2 processes (2.0 on two free cores; less where other work holds
    them), as the median, lowest and highest of ``rounds`` interleaved rounds (one round alone
    swung from below 1 to 2.6 on a shared VM whose speed changes within a second). The
    scaling figures are to be read against it."""
    import multiprocessing as mp
    import statistics

    ratios = []
    with mp.get_context("fork").Pool(2) as pool:
        pool.map(_busy, [0, 1])
        for _ in range(rounds):
            t1, _ = _timed(lambda: (_busy(0), _busy(1)))
            t2, _ = _timed(lambda: pool.map(_busy, [0, 1]))
            ratios.append(t1 / t2)
    return statistics.median(ratios), min(ratios), max(ratios)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=100, help="grid points per axis of the map")
    ap.add_argument("--loop-cases", type=int, default=300, help="cases timed in the loop")
    ap.add_argument("--mc", type=int, default=1000, help="Monte-Carlo runs")
    ap.add_argument("--quick", action="store_true", help="40 × 40 map, 200 runs")
    ap.add_argument("--repeat", type=int, default=3, help="Monte-Carlo timings: best of N")
    ap.add_argument("--rounds", type=int, default=9,
                    help="stability map, 1 -> 2 workers: interleaved rounds (medians)")
    ap.add_argument("--scaling-n", type=int, default=300,
                    help="also 1 -> 2 workers on an N x N map, where the work outweighs the "
                         "fixed costs of a run (0: not)")
    ap.add_argument("--ceiling-rounds", type=int, default=7,
                    help="the machine's own ceiling for 2 processes: median of N rounds")
    ap.add_argument("--only", choices=("map", "mc"), help="run one of the two parts")
    ap.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    args = ap.parse_args(argv)
    # the clusters' INFO lines (workers started, clients removed, ...) between the figures:
    # dask.distributed's own handler set to warnings, as its LocalCluster does while it starts
    try:
        import distributed  # noqa: F401  (configures its logging on import)
    except ImportError:
        pass
    for handler in logging.getLogger("distributed").handlers:
        handler.setLevel(logging.WARNING)
    if args.quick:
        args.n, args.loop_cases, args.mc, args.rounds, args.scaling_n = 40, 100, 200, 3, 0
    # the studies' saved blocks in a folder of their own, removed when done; the working folder
    # back afterwards (a relative --json path, a test calling main)
    with tempfile.TemporaryDirectory() as tmp, contextlib.chdir(tmp):
        res = {"cpus": os.cpu_count(), "load_before": os.getloadavg(),
               "ceiling_before": machine_ceiling(args.ceiling_rounds)}
        if args.only != "mc":
            res["stability_map"] = stability_map(args.n, args.loop_cases, args.rounds)
            if args.scaling_n:
                res["stability_map_scaling"] = map_scaling(args.scaling_n, args.rounds)
        if args.only != "map":
            res["monte_carlo"] = monte_carlo(args.mc, args.repeat)
        res.update(ceiling_after=machine_ceiling(args.ceiling_rounds), load_after=os.getloadavg())
    if "stability_map" in res:
        _print_map(res["stability_map"])
    if "stability_map_scaling" in res:
        _print_scaling(res["stability_map_scaling"])
    if "monte_carlo" in res:
        _print_mc(res["monte_carlo"])
    (b, b_lo, b_hi), (a, a_lo, a_hi) = res["ceiling_before"], res["ceiling_after"]
    print(f"this machine's own ceiling for 2 processes (pure-Python busy loop, median of "
          f"{args.ceiling_rounds} rounds): {b:.2f}x ({b_lo:.2f}-{b_hi:.2f}) before, "
          f"{a:.2f}x ({a_lo:.2f}-{a_hi:.2f}) after "
          f"({res['cpus']} CPUs; load average {res['load_before'][0]:.1f} before, "
          f"{res['load_after'][0]:.1f} after)")
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=1))
    return res


def _print_map(m: dict) -> None:
    print(f"stability map, {m['cases']} cases of {ROTOR.name} (set-up {m['setup_s']:.2f} s):")
    print(f"  loop over stability(lin):          {m['loop_cases_per_s']:10.0f} cases/s")
    print(f"  loop over the compiled lin:        {m['compiled_loop_cases_per_s']:10.0f} cases/s")
    print(f"  batched (run_study, 1 process):    {m['batched_cases_per_s']:10.0f} cases/s  "
          f"{m['speedup_vs_loop']:.0f}x the loop, {m['speedup_vs_compiled_loop']:.0f}x the "
          f"compiled loop; verdicts agree {m['verdicts_agree']}")
    _print_workers(m)
    print(f"  loop calling System.linearize per case: {m['relinearize_loop_cases_per_s']:.1f} "
          f"cases/s (batched: {m['speedup_vs_relinearize_loop']:.0f}x)")


def _print_scaling(m: dict) -> None:
    print(f"stability map, {m['cases']} cases, 1 -> 2 workers alone:")
    _print_workers(m)


def _print_workers(m: dict) -> None:
    print(f"  1 -> 2 workers, medians of {m['rounds']} interleaved rounds (identical to the serial "
          f"run: {all(m['identical'].values())}):")
    print(f"    run_study, 1 worker {m['1_worker_s']:.3f} s; 2 workers (threads) "
          f"{m['2_workers_s']:.3f} s: {m['threads_speedup']:.2f}x; 2 fresh processes "
          f"{m['2_processes_s']:.3f} s: {m['processes_speedup']:.2f}x")
    if "dask_2_s" in m:
        print(f"    Dask LocalCluster (warm): 1 worker {m['dask_1_s']:.3f} s, 2 workers "
              f"{m['dask_2_s']:.3f} s: {m['dask_speedup']:.2f}x (ceiling in those rounds: "
              f"{m['dask_lapack_ceiling']:.2f}x)")
    if "dask_free_cores_bound" in m:
        print(f"    Dask's fixed costs, a 4-case study: 1 worker {m['dask_fixed_1_s'] * 1e3:.1f} "
              f"ms, 2 workers {m['dask_fixed_2_s'] * 1e3:.1f} ms; on two free cores (the "
              f"1-worker run's work halved, those costs kept) 1 -> 2 would give "
              f"{m['dask_free_cores_bound']:.2f}x")
    print(f"    ceiling now: the map's eigenvalues alone (LAPACK, no GIL), 1 thread "
          f"{m['lapack_1_thread_s']:.3f} s, 2 threads {m['lapack_2_threads_s']:.3f} s: "
          f"{m['lapack_ceiling']:.2f}x")


def _print_mc(c: dict) -> None:
    print(f"Monte-Carlo, {c['runs']} runs of {CAR.name} (best of {c['repeat']}), runs per second; "
          f"identical to the per-case serial run:")
    print(f"  {'':28s}{'1 worker':>12s}{'2 workers':>12s}{'1 -> 2':>8s}")
    print(f"  {'per case (simulate() each)':28s}{c['per_case_1_runs_per_s']:12.0f}"
          f"{c['per_case_2_processes_runs_per_s']:12.0f}{c['per_case_1_to_2']:7.2f}x"
          f"  (2 processes; identical: {c['per_case_2_processes_identical']})")
    print(f"  {'ensemble, threads':28s}{c['ensemble_1_runs_per_s']:12.0f}"
          f"{c['ensemble_2_threads_runs_per_s']:12.0f}{c['ensemble_1_to_2_threads']:7.2f}x"
          f"  (identical: {c['ensemble_1_identical']}, {c['ensemble_2_threads_identical']})")
    print(f"  {'ensemble, processes':28s}{c['ensemble_1_runs_per_s']:12.0f}"
          f"{c['ensemble_2_processes_runs_per_s']:12.0f}{c['ensemble_1_to_2_processes']:7.2f}x"
          f"  (identical: {c['ensemble_2_processes_identical']})")
    print(f"  ensemble / per case: {c['ensemble_vs_per_case_1']:.2f}x on 1 worker, "
          f"{c['ensemble_vs_per_case_2']:.2f}x on 2 (threads against processes); the C "
          f"integration alone: {c['c_only_1_s']:.2f} s on 1 thread, {c['c_only_2_s']:.2f} s "
          f"on 2 ({100 * c['c_share_of_ensemble_1']:.0f} % of the 1-worker ensemble study); "
          f"max |z_b| {c['max_abs_z_b_mean_mm']:.2f} ± {c['max_abs_z_b_std_mm']:.2f} mm")
    print(f"  lock-step bound: {c['nfev_total']} right-hand sides, {c['c_ns_per_evaluation']:.0f} ns "
          f"of C integration each, of which the model's M, k, q {c['mkq_ns']:.0f} ns "
          f"({100 * c['mkq_share_of_c']:.0f} %: what one vectorized right-hand side over the "
          f"cases could speed up; each case's step loop remains)")
    if "dask_2_workers_s" in c:
        print(f"  ensembles on a Dask LocalCluster (warm, medians of {c['repeat']} interleaved "
              f"rounds): 1 worker {c['dask_1_workers_s']:.2f} s, "
              f"2 workers {c['dask_2_workers_s']:.2f} s: {c['dask_speedup']:.2f}x (identical: "
              f"{c['dask_1_identical']}, {c['dask_2_identical']})")


if __name__ == "__main__":
    main()
