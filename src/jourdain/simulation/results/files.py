"""Results in files (the formats are described in :mod:`jourdain.simulation.results`): HDF5
and CSV written through a temporary file and renamed, read back, xarray datasets, and the
incremental writing of a run that saves as it goes.
"""

from __future__ import annotations

import json
import os
import re
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Self, TypeVar

import numpy as np

from ...errors import EvaluationError, JourdainError
from ...units import (
    model_units,
    unit_of,
)
from .energies import WithEnergies

if TYPE_CHECKING:
    from ...model.system import System

#: how long an HDF5 file whose lock is held is waited for (h5_file)
LOCK_WAIT_S = 2.0


def h5_file(path: str | Path, mode: str) -> Any:
    """``h5py.File(path, mode)``, waiting up to :data:`LOCK_WAIT_S` while another holds the
    file's lock. A compiler started by a thread of this process (a model's library built in
    the background while its first run is interpreted) holds a copy of every open descriptor
    from its fork to its exec, and with it the lock of an HDF5 file that this process has
    just closed: a moment later the lock is free. Held longer (another process writing the
    file), the error is raised."""
    import h5py

    deadline = time.monotonic() + LOCK_WAIT_S
    while True:
        try:
            return h5py.File(path, mode)
        except BlockingIOError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.005)



FORMAT = "jourdain-results"
VERSION = 1


_R = TypeVar("_R", bound="WithFiles")


class WithFiles(WithEnergies):
    """Results written to and read from files (HDF5, CSV) and xarray."""

    def _columns(self) -> tuple[list[str], np.ndarray]:
        cols = ["t", *self.coordinate_names, *(f"{n}_d" for n in self.coordinate_names),
                *(f"{n}_dd" for n in self.coordinate_names), *self.input_names, "W"]
        data = [self.t[:, None], self.y, self.yd, self.ydd, self.u, self.W[:, None]]
        if self.system is not None or "T" in self._energies:
            try:
                T, V = self.kinetic_energy, self.potential_energy
                cols += ["T", "V"]
                data += [T[:, None], V[:, None]]
            except JourdainError:
                pass
        return cols, np.hstack(data)

    def _meta(self) -> dict[str, Any]:
        return {"format": FORMAT, "version": VERSION, "system": self.name,
                "method": self.method, "rtol": float(self.rtol), "status": self.status,
                "message": self.message, "coordinates": json.dumps(self.coordinate_names),
                "inputs": json.dumps(self.input_names),
                "parameters": json.dumps(self.parameters), "units": json.dumps(self.units),
                "nfev": int(self.nfev), "nsteps": int(self.nsteps),
                "wall_time": float(self.wall_time)}

    def to_xarray(self) -> Any:
        """These results as an ``xarray.Dataset`` (time, coordinate; units and the model's
        hash as attributes; ``jourdain[study]``):
        :func:`jourdain.simulation.labelled.results_dataset`."""
        from ..labelled import results_dataset  # xarray, optional (labelled arrays on this floor)

        return results_dataset(self)

    def save(self, path: str | Path) -> Path:
        """Write to ``.h5``/``.hdf5`` (HDF5, see module docs) or ``.csv``, through a temporary
        file renamed over ``path`` (an interruption leaves the previous file whole)."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".csv", ".h5", ".hdf5"):
            raise EvaluationError(f"unknown results file type {path.suffix!r}: use .h5 or .csv")
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp{suffix}")
        try:
            if suffix == ".csv":
                cols, data = self._columns()
                meta = {**self._meta(),
                        "column_units": json.dumps([self.unit(c) for c in cols])}
                with open(tmp, "w", encoding="utf-8") as fh:
                    fh.write(_csv_header(meta, cols))
                    np.savetxt(fh, data, delimiter=",", fmt="%.17g")
            else:
                self._save_h5(tmp)
            os.replace(tmp, path)
        finally:
            if tmp.exists():
                tmp.unlink()
        return path

    def _save_h5(self, path: Path) -> None:
        with h5_file(path, "w") as h:
            for k, v in self._meta().items():
                h.attrs[k] = v
            h["t"] = self.t
            for name, arr, cols in (("y", self.y, self.coordinate_names),
                                    ("yd", self.yd, [f"{n}_d" for n in self.coordinate_names]),
                                    ("ydd", self.ydd, [f"{n}_dd" for n in self.coordinate_names]),
                                    ("u", self.u, self.input_names)):
                h[name] = arr
                h[name].attrs["columns"] = json.dumps(cols)
                h[name].attrs["units"] = json.dumps([self.unit(c) for c in cols])
            h["W"] = self.W
            if self.system is not None or "T" in self._energies:
                try:
                    h["T"] = self.kinetic_energy
                    h["V"] = self.potential_energy
                except JourdainError:
                    pass
            for name in ("t", "W", "T", "V"):  # one unit for a column of its own
                if name in h:
                    h[name].attrs["units"] = self.unit(name)
            grp = h.create_group("events")
            for name, ev in self.events.items():
                g = grp.create_group(name.replace("/", "_"))
                for k in ("t", "y", "yd"):
                    g[k] = ev[k]

    @classmethod
    def load(cls, path: str | Path, system: System | None = None) -> Self:
        """Read a results file written by :meth:`save` (``.h5`` or ``.csv``)."""
        path = Path(path)
        if path.suffix.lower() == ".csv":
            return _load_csv(cls, path, system)
        with h5_file(path, "r") as h:
            if h.attrs.get("format") != FORMAT:
                raise EvaluationError(f"{path} is not a jourdain results file")
            a = dict(h.attrs)
            names = json.loads(a["coordinates"])
            f = len(names)
            if "partial" in h and "t" not in h:
                x = h["partial/x"][()]
                t = h["partial/t"][()]
                y, yd, W = x[:, :f], x[:, f:2 * f], x[:, 2 * f]
                ydd = np.full_like(y, np.nan)
                u = np.zeros((len(t), len(json.loads(a["inputs"]))))
            else:
                t, y, yd, ydd, u, W = (h[k][()] for k in ("t", "y", "yd", "ydd", "u", "W"))
            energies = {k: h[k][()] for k in ("T", "V") if k in h}
            events = {}
            if "events" in h:
                for k, g in h["events"].items():
                    events[k] = {kk: g[kk][()] for kk in ("t", "y", "yd")}
        if energies and system is None:
            energies.update(conservative=False, nonconservative=())
        elif system is not None:
            energies = {}
        return cls(system, t, y, yd, ydd, u, W, json.loads(a["parameters"]),
                   method=str(a["method"]), rtol=float(a["rtol"]), status=str(a["status"]),
                   message=str(a["message"]), nfev=int(a["nfev"]), nsteps=int(a["nsteps"]),
                   wall_time=float(a["wall_time"]), events=events, coordinate_names=names,
                   input_names=json.loads(a["inputs"]), units=json.loads(a["units"]),
                   energies=energies, name=str(a["system"]))



def _load_csv(cls: type[_R], path: Path, system: System | None) -> _R:
    meta: dict[str, str] = {}
    header = ""
    with path.open() as fh:
        for line in fh:
            if line.startswith("# "):
                k, _, v = line[2:].rstrip("\n").partition(": ")
                meta[k] = v
            else:
                header = line.strip()
                break
    if meta.get("format") != FORMAT:
        raise EvaluationError(f"{path} is not a jourdain results CSV file")
    cols = header.split(",")
    data = np.loadtxt(path, delimiter=",", comments="#", skiprows=len(meta) + 1, ndmin=2)
    names = json.loads(meta["coordinates"])
    inputs = json.loads(meta["inputs"])
    col = {c: i for i, c in enumerate(cols)}

    def block(keys: list[str], missing: float = 0.0) -> np.ndarray:
        if all(k in col for k in keys):
            return data[:, [col[k] for k in keys]] if keys else np.zeros((len(data), 0))
        return np.full((len(data), len(keys)), missing)  # a partial file: t, y, ẏ, W only

    energies = {}
    if "T" in col and system is None:
        energies = {"T": data[:, col["T"]], "V": data[:, col["V"]], "conservative": False,
                    "nonconservative": ()}
    return cls(system, data[:, 0], block(names), block([f"{n}_d" for n in names]),
                   block([f"{n}_dd" for n in names], np.nan), block(inputs), data[:, col["W"]],
                   json.loads(meta["parameters"]), method=meta.get("method", ""),
                   rtol=float(meta.get("rtol", "nan")), status=meta.get("status", ""),
                   message=meta.get("message", ""), nfev=int(meta.get("nfev", 0)),
                   nsteps=int(meta.get("nsteps", 0)),
                   wall_time=float(meta.get("wall_time", 0.0)), coordinate_names=names,
                   input_names=inputs, units=json.loads(meta["units"]), energies=energies,
                   name=meta.get("system", ""))


# --- incremental writing ------------------------------------------------------------------------
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


def _csv_header(meta: dict[str, Any], cols: Sequence[str]) -> str:
    """The comment lines of a results CSV, one per item (a line break in a name or message
    becomes a space, other control characters are written escaped, so that no value shifts
    the header), and the line of column names."""
    lines = [f"# {k}: " + _CONTROL.sub(lambda m: repr(m.group())[1:-1],
                                       " ".join(str(v).splitlines()))
             for k, v in meta.items()]
    return "\n".join([*lines, ",".join(cols)]) + "\n"


class _PartialCsv:
    """A results CSV filled row by row while a run goes: ``t, <y>, <y>_d, W`` under
    ``status: running``; :meth:`Results.save` replaces it with the complete file."""

    def __init__(self, path: str | Path, system: System) -> None:
        names = system.coordinate_names
        units = model_units(system)
        cols = ["t", *names, *(f"{n}_d" for n in names), "W"]
        meta = {"format": FORMAT, "version": VERSION, "system": system.name, "method": "",
                "rtol": float("nan"), "status": "running",
                "message": "run in progress (or killed): the rows hold the accepted steps "
                           "(t, y, ẏ, W)",
                "coordinates": json.dumps(names), "inputs": json.dumps(system.input_names),
                "parameters": json.dumps(system.parameter_values),
                "units": json.dumps(units), "nfev": 0, "nsteps": 0,
                "wall_time": 0.0,
                "column_units": json.dumps([unit_of(c, units, names) for c in cols])}
        self.fh = open(path, "w", encoding="utf-8")  # noqa: SIM115 - closed by close()
        self.fh.write(_csv_header(meta, cols))
        self.fh.flush()

    def append(self, t: np.ndarray, x: np.ndarray) -> None:
        np.savetxt(self.fh, np.column_stack([t, x]), delimiter=",", fmt="%.17g")
        self.fh.flush()

    def close(self) -> None:
        self.fh.close()


def open_incremental(path: str | Path, system: System) -> Any:
    """Create a results file (``.h5``, ``.hdf5`` or ``.csv``) that :func:`append_incremental`
    fills while a run goes."""
    if Path(path).suffix.lower() == ".csv":
        return _PartialCsv(path, system)
    n = 2 * system.f + 1
    h = h5_file(path, "w")
    h.attrs["format"] = FORMAT
    h.attrs["version"] = VERSION
    h.attrs["system"] = system.name
    h.attrs["status"] = "running"
    h.attrs["message"] = "run in progress (or killed): /partial holds the accepted steps"
    h.attrs["coordinates"] = json.dumps(system.coordinate_names)
    h.attrs["inputs"] = json.dumps(system.input_names)
    h.attrs["parameters"] = json.dumps(system.parameter_values)
    h.attrs["units"] = json.dumps(model_units(system))
    for k, v in (("method", ""), ("rtol", float("nan")), ("nfev", 0), ("nsteps", 0),
                 ("wall_time", 0.0)):
        h.attrs[k] = v
    g = h.create_group("partial")
    g.create_dataset("t", shape=(0,), maxshape=(None,), dtype=float, chunks=(1024,))
    g.create_dataset("x", shape=(0, n), maxshape=(None, n), dtype=float, chunks=(1024, n))
    h.flush()
    return h


def append_incremental(h: Any, t: np.ndarray, x: np.ndarray) -> None:
    """Append accepted steps and flush, so the file is readable if the process dies."""
    if len(t) == 0:
        return
    if isinstance(h, _PartialCsv):
        h.append(t, x)
        return
    dt, dx = h["partial/t"], h["partial/x"]
    m = dt.shape[0]
    dt.resize((m + len(t),))
    dx.resize((m + len(t), dx.shape[1]))
    dt[m:] = t
    dx[m:] = x


def mark_interrupted(path: str | Path, message: str) -> bool:
    """Set the ``status`` of a results file (complete, or partial: a run that wrote as it
    went) to ``interrupted`` with ``message``, keeping its data: for a command stopped by
    Ctrl-C after the run's own handling (while the results were assembled or saved, or after),
    so that no file it wrote claims ``running`` or ``finished``. A CSV is rewritten through a
    temporary file (its rows copied, a last row cut short by the interruption dropped); HDF5
    attributes are set in place. Returns False where ``path`` is no results file."""
    path = Path(path)
    text = " ".join(message.split())
    if path.suffix.lower() != ".csv":
        try:
            with h5_file(path, "r+") as h:
                if h.attrs.get("format") != FORMAT:
                    return False
                if h.attrs.get("status") != "interrupted":  # else its own message stays
                    h.attrs["status"] = "interrupted"
                    h.attrs["message"] = text
        except OSError:
            return False
        return True
    tmp = path.with_name(f".{path.name}.{os.getpid()}.mark.tmp")
    try:
        with path.open(encoding="utf-8") as src, tmp.open("w", encoding="utf-8") as dst:
            first = src.readline()
            if first.rstrip("\n") != f"# format: {FORMAT}":
                return False
            dst.write(first)
            width = None
            keep = False  # interrupted already: its own message stays
            for line in src:
                if line.startswith("# status: "):
                    keep = line == "# status: interrupted\n"
                    line = "# status: interrupted\n"
                elif line.startswith("# message: ") and not keep:
                    line = _csv_header({"message": text}, []).splitlines()[0] + "\n"
                elif not line.startswith("#"):
                    if width is None:
                        width = line.count(",")  # the column names
                    elif not line.endswith("\n") or line.count(",") != width:
                        continue  # a row cut short
                dst.write(line)
        os.replace(tmp, path)
    except (OSError, UnicodeDecodeError):
        return False
    finally:
        if tmp.exists():
            tmp.unlink()
    return True
