"""Running a study: serially, on the local machine's cores, or on a Dask cluster.

The cases are cut into blocks of ``spec.block`` cases, the unit of work and of saving.
Each block is computed by :func:`jourdain.study.compute.compute_block` in a worker that rebuilt
the model from the study's copy of the model file (its hash checked) and loaded the compiled
functions from the on-disk cache (their content keys checked against the study's). With an
output file, every finished block is saved at once (``<out>.parts/``, one ``.npz`` per block,
written to a temporary name and renamed); a study run again with the same output file resumes
from the blocks saved, and the assembled results equal those of an uninterrupted run (every
case's numbers depend on that case alone). The parts are removed once the NetCDF file is
written.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import time
from collections.abc import Callable, Iterator
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from ..extras import missing
from .compute import compute_block, context, output_layout
from .spec import StudyError, StudySpec

__all__ = ["Progress", "run_study"]

_PARTS_FORMAT = "jourdain-study-parts-1"


class Progress:
    """A progress bar on stderr (``[#####-----] 512/1000 cases, 3 failed, 1.2 s``), redrawn at
    most every ``interval`` seconds; in a Jupyter notebook, the same line in the cell's output,
    updated in place; on a stream that is not a terminal, one line at the end. ``quiet``:
    nothing."""

    def __init__(self, total: int, quiet: bool = False, stream: Any = None,
                 interval: float = 0.2, label: str = "cases") -> None:
        self.total = total
        self.quiet = quiet
        self.stream = stream if stream is not None else sys.stderr
        self.interval = interval
        self.label = label
        self.done = 0
        self.failed = 0
        self.start = time.perf_counter()
        self._last = -1.0
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.handle = None
        if not quiet and stream is None and not self.tty and "ipykernel" in sys.modules:
            try:
                from IPython.display import Pretty, display

                self._pretty = Pretty
                self.handle = display(Pretty(self.line()), display_id=True)
            except ImportError:  # a kernel without IPython's display: the line at the end
                self.handle = None

    def update(self, done: int, failed: int = 0) -> None:
        self.done += done
        self.failed += failed
        now = time.perf_counter()
        if self.quiet or not (self.tty or self.handle) or (now - self._last < self.interval
                                                           and self.done < self.total):
            return
        self._last = now
        if self.handle is not None:
            self.handle.update(self._pretty(self.line()))
            return
        self.stream.write("\r" + self.line())
        self.stream.flush()

    def line(self) -> str:
        width = 30
        frac = self.done / self.total if self.total else 1.0
        bar = "#" * int(round(width * frac)) + "-" * (width - int(round(width * frac)))
        fail = f", {self.failed} failed" if self.failed else ""
        return (f"[{bar}] {self.done}/{self.total} {self.label}{fail}, "
                f"{time.perf_counter() - self.start:.1f} s")

    def close(self) -> None:
        if self.quiet:
            return
        if self.handle is not None:
            self.handle.update(self._pretty(self.line()))
            return
        self.stream.write(("\r" if self.tty else "") + self.line() + "\n")
        self.stream.flush()


def _blocks(spec: StudySpec) -> list[tuple[int, int]]:
    n, b = spec.n_cases, spec.block
    return [(s, min(s + b, n)) for s in range(0, n, b)]


class _Parts:
    """The saved blocks of a study (``<out>.parts/``)."""

    def __init__(self, out: Path, spec: StudySpec, keys: dict[str, str], force: bool,
                 force_name: str = "force=True") -> None:
        self.dir = Path(str(out) + ".parts")
        manifest = {"format": _PARTS_FORMAT, "spec_hash": spec.spec_hash,
                    "model_hash": spec.model_hash, "n_cases": spec.n_cases,
                    "block": spec.block, "keys": keys}
        mfile = self.dir / "manifest.json"
        if self.dir.exists():
            try:  # an interrupted run's manifest says so: the parts are the same
                old = {k: v for k, v in json.loads(mfile.read_text()).items()
                       if k not in ("status", "message")}
            except (OSError, ValueError, AttributeError):
                old = None
            if old != manifest:
                if not force:
                    raise StudyError(f"{self.dir} holds the saved parts of another study (or "
                                     f"another model or jourdain); delete it, or pass "
                                     f"{force_name} to start afresh", spec.filename)
                shutil.rmtree(self.dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        if not mfile.exists():
            tmp = mfile.with_suffix(".tmp")
            tmp.write_text(json.dumps(manifest, indent=1))
            os.replace(tmp, mfile)

    def path(self, start: int, stop: int) -> Path:
        return self.dir / f"block-{start:09d}-{stop:09d}.npz"

    def load(self, start: int, stop: int) -> dict[str, Any] | None:
        p = self.path(start, stop)
        if not p.exists():
            return None
        try:
            with np.load(p, allow_pickle=False) as z:
                outputs = {k[4:]: z[k] for k in z.files if k.startswith("out_")}
                errors = [str(e) for e in z["errors"]]
        except (OSError, ValueError, KeyError):  # a damaged part: computed again
            return None
        return {"start": start, "stop": stop, "outputs": outputs, "errors": errors}

    def save(self, block: dict[str, Any]) -> None:
        p = self.path(block["start"], block["stop"])
        tmp = p.with_name(p.name + ".tmp.npz")
        arrays = {f"out_{k}": v for k, v in block["outputs"].items()}
        np.savez(tmp, errors=np.array(block["errors"], dtype=str), **arrays)
        os.replace(tmp, p)

    def remove(self) -> None:
        shutil.rmtree(self.dir, ignore_errors=True)


def _init_worker() -> None:
    """A fresh worker process: forget what it inherited, so that it rebuilds the model from
    the study's model text and loads the compiled functions from the disk cache."""
    from .. import numeric
    from .context import forget_contexts

    forget_contexts()
    numeric.clear_cache()


def _result(fut: Any, spec: StudySpec) -> dict[str, Any]:
    """A block's result; a block that failed as a whole (not one of its cases: a worker that
    died, another jourdain on a cluster node) stops the study with a StudyError naming it (the
    blocks saved so far stay, for a later run to resume from)."""
    try:
        return fut.result()
    except StudyError:
        raise
    except Exception as exc:  # from another process: any type; re-raised as the study's error
        raise StudyError(f"a block of the study failed in its worker: {type(exc).__name__}: "
                         f"{exc}", spec.filename) from exc


def _run_local(spec: StudySpec, todo: list[tuple[int, int]], workers: int,
               keys: dict[str, str]) -> Iterator[dict[str, Any]]:
    import concurrent.futures as cf
    import multiprocessing as mp

    method = "fork" if "fork" in mp.get_all_start_methods() else "spawn"
    with cf.ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context(method),
                                initializer=_init_worker) as pool:
        yield from _stream(pool, spec, todo, keys)


def _run_threads(spec: StudySpec, todo: list[tuple[int, int]], workers: int,
                 keys: dict[str, str]) -> Iterator[dict[str, Any]]:
    """The blocks on threads of this process: for work that releases the GIL (the ensembles of
    simulations run in C), with no worker start and no model rebuilt."""
    import concurrent.futures as cf

    with _one_blas_thread(), cf.ThreadPoolExecutor(max_workers=workers) as pool:
        yield from _stream(pool, spec, todo, keys)


def _one_blas_thread() -> Any:
    """BLAS/LAPACK on one thread while the study's threads run (each of them calls LAPACK for
    its own block: more threads than cores otherwise); without threadpoolctl (the ``study``
    extra), as configured."""
    import contextlib

    try:
        controller = _blas_controller()
    except ImportError:
        return contextlib.nullcontext()
    return controller.limit(limits=1, user_api="blas")


@lru_cache(maxsize=1)
def _blas_controller() -> Any:
    """threadpoolctl's controller, made once (it scans the loaded libraries: 1.6 ms)."""
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def _stream(pool: Any, spec: StudySpec, todo: list[tuple[int, int]],
            keys: dict[str, str]) -> Iterator[dict[str, Any]]:
    """The blocks submitted to a local pool (processes or threads), yielded as they finish;
    the ones not started are cancelled when the caller stops early (an error, Ctrl-C)."""
    import concurrent.futures as cf

    futures = [pool.submit(compute_block, spec, s, e, keys) for s, e in todo]
    try:
        for fut in cf.as_completed(futures):
            yield _result(fut, spec)
    finally:
        for fut in futures:
            fut.cancel()


#: how local workers run: ``auto`` picks threads where the work releases the GIL
POOLS = ("auto", "processes", "threads")


def _releases_gil(ctx: Any) -> bool:
    """True when a block's work runs in C and LAPACK with the GIL released: the evaluations
    and linearizations (one C call for the block, stacked solves and eigenvalues), frequency
    responses, critical values, and simulations advanced as an ensemble; False for simulations
    run case by case (``simulate()`` per case spends much of its time in Python) and for
    closed systems (linearized and simulated case by case)."""
    if ctx.closed:  # a closed system's cases: one linearization or simulate() each, in Python
        return False
    return "simulate" not in ctx.spec.compute or ctx.ensemble is not None


def _compute_blocks(spec: StudySpec, todo: list[tuple[int, int]], keys: dict[str, str]
                    ) -> list[dict[str, Any]]:
    """Several blocks in one task (a cluster's task): computed one after the other."""
    return [compute_block(spec, s, e, keys) for s, e in todo]


#: the most blocks in one Dask task. A task's blocks reach the client, and are saved, when the
#: task ends, so this bounds what an interrupted study loses per worker thread (16 blocks:
#: 8 192 cases at the default block size). Below it a thread gets one task: each task costs
#: the scheduler and the client a few ms of Python, on the workers' cores where the cluster
#: is local, and its worker a gap of 1 to 3 ms before the next. Measured on the 10 000-case map
#: (20 blocks), 2-worker LocalCluster, alternated runs: the client process's CPU per run 39 ms
#: with four tasks per thread, 21 ms with one; 1 → 2 workers 1.23× against 1.52×
BLOCKS_PER_TASK = 16


def _groups(todo: list[tuple[int, int]], threads: int) -> list[list[tuple[int, int]]]:
    """``todo`` as the tasks of a cluster of ``threads`` worker threads: as few as keep every
    thread busy and hold at most :data:`BLOCKS_PER_TASK` blocks each, of sizes that differ by
    one block at most. A task takes every n-th block (task k: blocks k, k + n, ...), so that a
    region of the parameter space where cases cost more (a stiff simulation, a slow bisection)
    is shared by all tasks instead of falling to one."""
    threads = max(1, threads)
    per_thread = -(-len(todo) // threads)
    # none where every block was saved already (a resumed study submits no task)
    n = min(threads * max(1, -(-per_thread // BLOCKS_PER_TASK)), len(todo))
    return [todo[k::n] for k in range(n)]


def _run_dask(spec: StudySpec, todo: list[tuple[int, int]], scheduler: Any,
              keys: dict[str, str]) -> Iterator[dict[str, Any]]:
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise missing("A study on a Dask cluster (dask.distributed)", "study",
                      "distributed") from None
    own = not isinstance(scheduler, Client)
    try:
        client = Client(scheduler) if own else scheduler
    except (OSError, TimeoutError, ValueError) as exc:
        raise StudyError(f"cannot reach the Dask scheduler at {scheduler!r}: {exc}",
                         spec.filename) from None
    try:
        threads = sum(w.get("nthreads", 1)
                      for w in client.scheduler_info()["workers"].values()) or 1
        groups = _groups(todo, threads)
        # all tasks in one message to the scheduler: a client sends what it is given within
        # 10 ms of its last message in its next batch, so that tasks submitted one by one
        # reached an idle second worker 10 ms after the first. The spec (a few kB: the study
        # and model texts) travels with each task; a scattered copy, content-keyed, raced
        # with its release when the same study ran again
        futures = client.map(_compute_blocks, [spec] * len(groups), groups,
                             [keys] * len(groups), pure=False)
        try:
            # results gathered as they finish, in batches: one round trip for several tasks;
            # on this client's loop (as_completed takes the default client's otherwise, and
            # waits forever where the process has another client, created later)
            for fut, res in as_completed(futures, loop=client.loop, with_results=True,
                                         raise_errors=False):
                if fut.status == "error":
                    _result(fut, spec)  # raises the task's error as the study's
                yield from res
        finally:
            client.cancel([f for f in futures if not f.done()])
    finally:
        if own:
            client.close()


def run_study(spec: StudySpec, out: str | Path | None = None, *, workers: int | None = None,
              scheduler: Any = None, quiet: bool = False, force: bool = False,
              pool: str = "auto", on_block: Callable[[dict[str, Any]], None] | None = None,
              force_name: str = "force=True") -> Any:
    """Run ``spec`` and return its results as an ``xarray.Dataset``
    (:func:`jourdain.study.dataset.to_dataset`).

    Parameters
    ----------
    spec : StudySpec (:func:`jourdain.study.load_study`)
    out : path of the NetCDF file to write (``.nc``); blocks are saved as they finish in
        ``<out>.parts/`` and a study run again with the same ``out`` resumes from them
    workers : workers on this machine (None, the default: one per core; 1: in this
        process; a study of one block always runs in this process)
    pool : how the local workers run: ``"processes"`` (each rebuilds the model),
        ``"threads"`` (for work that releases the GIL) or ``"auto"`` (the default: threads,
        BLAS on one thread each, unless the study simulates case by case: processes)
    scheduler : address of a ``dask.distributed`` scheduler (``"tcp://host:8786"``) or a
        ``distributed.Client``: the blocks run on that cluster (``workers`` is then ignored),
        grouped into one task per worker thread, or more of at most 16 blocks each
    quiet : no progress bar (:class:`Progress`: on stderr, or in the notebook's cell)
    force : start afresh where ``<out>.parts/`` holds another study's parts, and replace an
        existing ``out``
    on_block : called with every block computed in this run (after it was saved)
    force_name : how the messages name ``force`` (the command line's ``--force``)

    Failed cases do not stop the study: their outputs are NaN (verdict −1) and their error is
    in the ``error`` variable.
    """
    from .dataset import to_dataset

    if out is not None:
        out = Path(out)
        if out.exists() and not force:
            raise StudyError(f"{out} exists; pass {force_name} to replace it",
                             spec.filename)
    ctx = context(spec)  # derives and compiles once here: errors of the model show at once
    keys = dict(ctx.keys)
    layout = output_layout(ctx)
    blocks = _blocks(spec)
    parts = _Parts(out, spec, keys, force, force_name) if out is not None else None
    results: dict[int, dict[str, Any]] = {}
    if parts is not None:
        for s, e in blocks:
            saved = parts.load(s, e)
            if saved is not None and set(saved["outputs"]) == set(layout):
                results[s] = saved
    todo = [(s, e) for s, e in blocks if s not in results]
    bar = Progress(spec.n_cases, quiet=quiet)
    bar.update(sum(b["stop"] - b["start"] for b in results.values()),
               sum(1 for b in results.values() for e in b["errors"] if e))
    if scheduler is not None:
        stream = _run_dask(spec, todo, scheduler, keys)
    else:
        n = (os.cpu_count() or 1) if workers is None else int(workers)
        if n < 1:
            raise StudyError(f"workers must be ≥ 1, got {workers}", spec.filename)
        if pool not in POOLS:
            raise StudyError(f"pool must be one of {', '.join(POOLS)}, got {pool!r}",
                             spec.filename)
        threads = pool == "threads" or (pool == "auto" and _releases_gil(ctx))
        if n > 1 and len(todo) > 1:
            stream = (_run_threads if threads else _run_local)(spec, todo, min(n, len(todo)),
                                                               keys)
        else:
            stream = (compute_block(spec, s, e, keys) for s, e in todo)
    for block in stream:
        if parts is not None:
            parts.save(block)
        results[block["start"]] = block
        bar.update(block["stop"] - block["start"], sum(1 for e in block["errors"] if e))
        if on_block is not None:
            on_block(block)
    bar.close()
    ds = to_dataset(ctx, [results[s] for s, _ in blocks])
    if out is not None and parts is not None:
        from .dataset import write_netcdf

        write_netcdf(ds, out)
        parts.remove()
    return ds
