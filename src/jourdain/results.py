"""Results of a simulation: time histories, energies, reaction forces, files and plots.

File format (HDF5, written with h5py; readable by h5py, MATLAB ``h5read``, Julia HDF5.jl,
HDFView, ...)::

    /            attributes: format = "jourdain-results", version = 1, system, method, rtol,
                 status, message, coordinates, inputs (JSON lists of names), parameters,
                 units (JSON objects), nfev, nsteps, wall_time
    /t           (N,)    time [s]
    /y           (N, f)  coordinates, columns named by the attribute "columns"
    /yd, /ydd    (N, f)  rates and accelerations
    /u           (N, nu) inputs
    /W           (N,)    work of the generalized applied forces q since t0
    /T, /V       (N,)    kinetic and potential energy (when the system was at hand)
    /events/<name>/t, y, yd

A run that writes as it goes (``simulate(..., output=path)``) first fills
``/partial/t`` (N,) and ``/partial/x`` (N, 2f+1: y, ẏ, W) and sets ``status = "running"``; the
complete layout replaces it when the run ends, so a crashed run leaves a readable file.

CSV (``.csv``): one header line of column names (``t, <y>, <y>_d, <y>_dd, <inputs>, W, T, V``)
after comment lines starting with ``#`` that hold the metadata.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import EvaluationError, JourdainError

if TYPE_CHECKING:
    from .model.system import System

FORMAT = "jourdain-results"
VERSION = 1


@lru_cache(maxsize=32)
def _energy_function(system: System) -> tuple[Any, bool, tuple[str, ...], bool]:
    from .energy import energy
    from .numeric import lambdify
    from .symbolic import SymMatrix

    e = energy(system.kinematics())
    fn = lambdify(system, {"T": SymMatrix.column([e.T]), "V": SymMatrix.column([e.V])})
    return fn, e.conservative, e.nonconservative, e.rheonomic


@lru_cache(maxsize=32)
def _positions_function(system: System) -> Any:
    from .numeric import lambdify

    kin = system.kinematics()
    mats = {}
    for bk in kin.bodies:
        mats[f"{bk.name}.r_O"] = bk.r_O
        mats[f"{bk.name}.r"] = bk.r
    return lambdify(system, mats)


class Results:
    """Time histories of a simulation (see :func:`jourdain.simulate.simulate`).

    Attributes
    ----------
    t : (N,) times
    y, yd, ydd : (N, f) coordinates, rates, accelerations
    u : (N, nu) inputs
    W : (N,) work of the generalized applied forces ``∫ ẏᵀq dt`` since t0
    parameters : parameter values used
    status : "finished", "event", "interrupted" (Ctrl-C or an exception in an input function)
    message : what happened, in words
    events : name -> {"t": (m,), "y": (m, f), "yd": (m, f)}
    nfev, nsteps, n_accepted, n_rejected, wall_time : cost of the run
    """

    def __init__(self, system: System | None, t: np.ndarray, y: np.ndarray, yd: np.ndarray,
                 ydd: np.ndarray, u: np.ndarray, W: np.ndarray, parameters: dict[str, float],
                 method: str = "", rtol: float = float("nan"), atol: Any = None,
                 status: str = "finished", message: str = "", nfev: int = 0, nsteps: int = 0,
                 n_accepted: int = 0, n_rejected: int = 0, wall_time: float = 0.0,
                 events: dict | None = None, exception: BaseException | None = None,
                 coordinate_names: Sequence[str] | None = None,
                 input_names: Sequence[str] | None = None,
                 units: dict[str, str] | None = None, energies: dict | None = None,
                 name: str | None = None) -> None:
        self.system = system
        self.t, self.y, self.yd, self.ydd, self.u, self.W = t, y, yd, ydd, u, W
        self.parameters = parameters
        self.method, self.rtol, self.atol = method, rtol, atol
        self.status, self.message = status, message
        self.nfev, self.nsteps = nfev, nsteps
        self.n_accepted, self.n_rejected = n_accepted, n_rejected
        self.wall_time = wall_time
        self.events = events or {}
        self.exception = exception
        self.coordinate_names = list(coordinate_names if coordinate_names is not None
                                     else system.coordinate_names)  # type: ignore[union-attr]
        self.input_names = list(input_names if input_names is not None
                                else system.input_names)  # type: ignore[union-attr]
        self.units = dict(units if units is not None else dict(system.units))  # type: ignore[union-attr]
        self.name = name if name is not None else (system.name if system else "")
        self._energies = dict(energies or {})

    # --- state ---------------------------------------------------------------------------
    @property
    def interrupted(self) -> bool:
        """True when the run was cut short (Ctrl-C, an exception in an input function)."""
        return self.status == "interrupted"

    @property
    def y_final(self) -> np.ndarray:
        return self.y[-1]

    @property
    def yd_final(self) -> np.ndarray:
        return self.yd[-1]

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        return (f"Results({self.name!r}: {len(self.t)} points, t = {self.t[0]:.4g} .. "
                f"{self.t[-1]:.4g}, status={self.status!r}, method={self.method}, "
                f"nfev={self.nfev})")

    def summary(self) -> str:
        """What happened, in a few lines: status, cost and, when the system is at hand, the
        relative energy drift (conservative model) or the energy balance error."""
        lines = [f"{self.name}: {self.status} - {self.message}",
                 f"  t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s, {len(self.t)} points, method "
                 f"{self.method}, rtol {self.rtol:g}",
                 f"  {self.n_accepted} steps accepted, {self.n_rejected} rejected, "
                 f"{self.nfev} right-hand sides, {1e3 * self.wall_time:.3f} ms"]
        try:
            if self.conservative:
                lines.append(f"  relative energy drift {self.energy_drift:.3e} (conservative model)")
            elif self._energies.get("rheonomic"):
                lines.append("  no energy balance: the prescribed (rheonomic) motion does work")
            else:
                lines.append(f"  energy balance error {self.energy_balance_error:.3e} "
                             f"(non-conservative: {', '.join(self._energies['nonconservative'])})")
        except JourdainError:
            pass
        return "\n".join(lines)

    def coordinate(self, name: str) -> np.ndarray:
        """Time history of one coordinate (or ``<name>_d`` / ``<name>_dd`` for its rates)."""
        for suffix, arr in (("_dd", self.ydd), ("_d", self.yd), ("", self.y)):
            base = name[: len(name) - len(suffix)] if suffix and name.endswith(suffix) else name
            if (not suffix or name.endswith(suffix)) and base in self.coordinate_names:
                return arr[:, self.coordinate_names.index(base)]
        raise EvaluationError(f'unknown coordinate "{name}"; coordinates are '
                              f"{self.coordinate_names}")

    # --- energies ---------------------------------------------------------------------------
    def _need_system(self, what: str) -> System:
        if self.system is None:
            raise JourdainError(f"{what} needs the system: these results were loaded from a "
                                "file; pass system= to Results.load")
        return self.system

    def _energy(self) -> None:
        if "T" in self._energies:
            return
        system = self._need_system("the energies")
        fn, cons, noncons, rheonomic = _energy_function(system)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        out = fn.batch(self.y, self.yd, self.t, p, None)
        self._energies.update(T=out["T"][:, 0, 0].copy(), V=out["V"][:, 0, 0].copy(),
                              conservative=cons, nonconservative=noncons, rheonomic=rheonomic)

    @property
    def kinetic_energy(self) -> np.ndarray:
        """``T = ½ Σ (m vᵀv + ωᵀIω)`` from the body velocities, (N,)."""
        self._energy()
        return self._energies["T"]

    @property
    def potential_energy(self) -> np.ndarray:
        """Potential of gravity, linear springs and linear generalized springs, (N,)."""
        self._energy()
        return self._energies["V"]

    @property
    def total_energy(self) -> np.ndarray:
        return self.kinetic_energy + self.potential_energy

    @property
    def work_nonconservative(self) -> np.ndarray:
        """Work of the non-conservative forces since t0: ``W + V − V(t0)``, (N,).

        ``W`` (integrated with the motion) is the work of all generalized applied forces; the
        conservative ones did ``−(V − V0)`` of it.
        """
        V = self.potential_energy
        return self.W + V - V[0]

    @property
    def conservative(self) -> bool:
        self._energy()
        return bool(self._energies["conservative"])

    @property
    def energy_drift(self) -> float | None:
        """Relative drift of ``T + V`` for a conservative model:
        ``max |E(t) − E(t0)| / max(|E(t0)|, max T)``; None for non-conservative models."""
        if not self.conservative:
            return None
        E = self.total_energy
        scale = max(abs(E[0]), float(np.max(np.abs(self.kinetic_energy))), 1e-300)
        return float(np.max(np.abs(E - E[0])) / scale)

    @property
    def rheonomic(self) -> bool:
        """The kinematics depends on time explicitly (a prescribed motion)."""
        self._energy()
        return bool(self._energies.get("rheonomic"))

    @property
    def energy_balance_error(self) -> float:
        """Relative error of ``T + V − W_nc = const``. Expected small for scleronomic models;
        for a rheonomic one (:attr:`rheonomic`) the prescribed motion does work that no force
        element accounts for, and the balance does not close."""
        bal = self.total_energy - self.work_nonconservative
        scale = max(float(np.max(np.abs(self.total_energy))), float(np.max(np.abs(self.kinetic_energy))),
                    1e-300)
        return float(np.max(np.abs(bal - bal[0])) / scale)

    # --- reactions and positions ----------------------------------------------------------
    @property
    def g(self) -> np.ndarray:
        """Generalized reaction forces ``g`` along the motion, (N, q) (columns: ``g_names``)."""
        if "g" not in self._energies:
            self._reactions()
        return self._energies["g"]

    @property
    def g_names(self) -> list[str]:
        if "g_names" not in self._energies:
            self._reactions()
        return self._energies["g_names"]

    def _reactions(self) -> None:
        system = self._need_system("the reaction forces")
        from .reactions import _reactions_function, projected_reactions, solve_g

        lay, fn = _reactions_function(system)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        U = self.u if self.u.shape[1] else None
        out = fn.batch(self.y, self.yd, self.t, p, U)
        qc, qe = out["q_c"][:, :, 0], out["q_e"][:, :, 0]
        N, kh, qh = projected_reactions(lay, out["M_bar"], out["Q_bar"], qc, qe)
        g = None
        if not lay.singular_rows:  # N̂ g = k̂ − q̂ for all states in one batched solve
            try:
                g = np.linalg.solve(N, (kh - qh)[:, :, None])[:, :, 0]
            except np.linalg.LinAlgError:
                g = None
        if g is None:  # bodies without inertia or redundant directions: state by state
            g = np.empty((len(self.t), N.shape[1]))
            for i in range(len(self.t)):
                g[i], _ = solve_g(out["Q_bar"][i], N[i], kh[i], qh[i], qc[i], qe[i],
                                  lay.singular_rows, lay.g_names)
        self._energies["g"] = g
        self._energies["g_names"] = list(lay.g_names)

    def positions(self, body: str, point: str = "origin") -> np.ndarray:
        """Inertial position of a body's frame origin (``point="origin"``) or centre of mass
        (``"com"``) along the motion, (N, 3) — for plots and animations."""
        system = self._need_system("positions")
        system.body(body)
        fn = _positions_function(system)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        out = fn.batch(self.y, self.yd, self.t, p, self.u if self.u.shape[1] else None)
        return out[f"{body}.r_O" if point == "origin" else f"{body}.r"][:, :, 0]

    # --- files ----------------------------------------------------------------------------
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

    def save(self, path: str | Path) -> Path:
        """Write to ``.h5``/``.hdf5`` (HDF5, see module docs) or ``.csv``."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".csv":
            cols, data = self._columns()
            header = "\n".join(f"{k}: {v}" for k, v in self._meta().items())
            np.savetxt(path, data, delimiter=",", header=header + "\n" + ",".join(cols),
                       comments="# ", fmt="%.17g")
            # the last header line is the column names without the comment mark
            text = path.read_text().splitlines()
            i = len(self._meta())
            text[i] = text[i][2:]
            path.write_text("\n".join(text) + "\n")
            return path
        if suffix not in (".h5", ".hdf5"):
            raise EvaluationError(f"unknown results file type {path.suffix!r}: use .h5 or .csv")
        import h5py

        with h5py.File(path, "w") as h:
            for k, v in self._meta().items():
                h.attrs[k] = v
            h["t"] = self.t
            for name, arr, cols in (("y", self.y, self.coordinate_names),
                                    ("yd", self.yd, [f"{n}_d" for n in self.coordinate_names]),
                                    ("ydd", self.ydd, [f"{n}_dd" for n in self.coordinate_names]),
                                    ("u", self.u, self.input_names)):
                h[name] = arr
                h[name].attrs["columns"] = json.dumps(cols)
            h["W"] = self.W
            if self.system is not None or "T" in self._energies:
                try:
                    h["T"] = self.kinetic_energy
                    h["V"] = self.potential_energy
                except JourdainError:
                    pass
            grp = h.create_group("events")
            for name, ev in self.events.items():
                g = grp.create_group(name.replace("/", "_"))
                for k in ("t", "y", "yd"):
                    g[k] = ev[k]
        return path

    @classmethod
    def load(cls, path: str | Path, system: System | None = None) -> Results:
        """Read a results file written by :meth:`save` (``.h5`` or ``.csv``)."""
        path = Path(path)
        if path.suffix.lower() == ".csv":
            return _load_csv(path, system)
        import h5py

        with h5py.File(path, "r") as h:
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

    # --- plots ----------------------------------------------------------------------------
    def _unit(self, name: str, order: int = 0) -> str:
        u = self.units.get(name)
        if u is None:
            return ""
        return u + ("" if order == 0 else "/s" if order == 1 else "/s^2")

    def _label(self, name: str, order: int) -> str:
        sym = name + ("" if order == 0 else "_d" if order == 1 else "_dd")
        unit = self._unit(name, order)
        return f"{sym} [{unit}]" if unit else sym

    def plot(self, what: str = "y", coordinates: Sequence[str] | None = None, ax: Any = None
             ) -> Any:
        """Time histories: ``what`` = "y", "yd", "ydd", "u", "energy" or "g" (reaction forces);
        returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        names = list(coordinates) if coordinates is not None else self.coordinate_names
        if what in ("y", "yd", "ydd"):
            order = ("y", "yd", "ydd").index(what)
            arr = (self.y, self.yd, self.ydd)[order]
            for n in names:
                if n not in self.coordinate_names:
                    raise EvaluationError(f'unknown coordinate "{n}"; coordinates are '
                                          f"{self.coordinate_names}")
                ax.plot(self.t, arr[:, self.coordinate_names.index(n)],
                        label=self._label(n, order))
            units = {self._unit(n, order) for n in names}
            ylabel = ["coordinates", "rates", "accelerations"][order]
            if len(units) == 1 and "" not in units:
                ylabel += f" [{units.pop()}]"
            ax.set_ylabel(ylabel)
        elif what == "u":
            for i, n in enumerate(self.input_names):
                ax.plot(self.t, self.u[:, i], label=n)
            ax.set_ylabel("inputs")
        elif what == "energy":
            ax.plot(self.t, self.kinetic_energy, label="T (kinetic)")
            ax.plot(self.t, self.potential_energy, label="V (potential)")
            ax.plot(self.t, self.total_energy, label="T + V")
            ax.plot(self.t, self.work_nonconservative, label="W_nc (non-conservative work)")
            ax.set_ylabel("energy [J]")
        elif what == "g":
            for i, n in enumerate(self.g_names):
                ax.plot(self.t, self.g[:, i], label=n)
            ax.set_ylabel("reaction forces g [N, N·m]")
        else:
            raise EvaluationError(f"plot: what must be y, yd, ydd, u, energy or g, got {what!r}")
        ax.set_xlabel("t [s]")
        ax.set_title(self.name)
        ax.legend()
        ax.grid(True)
        return ax

    def plot_path(self, body: str, plane: str = "xy", point: str = "origin", ax: Any = None
                  ) -> Any:
        """Path of a body's frame origin (or ``point="com"``) projected on a coordinate plane
        of the inertial frame ("xy", "xz", "yz"); returns the Axes."""
        import matplotlib.pyplot as plt

        if len(plane) != 2 or set(plane) - set("xyz"):
            raise EvaluationError(f'plane must be two of "x", "y", "z", got {plane!r}')
        r = self.positions(body, point)
        i, j = ("xyz".index(plane[0]), "xyz".index(plane[1]))
        if ax is None:
            _, ax = plt.subplots()
        unit = self.units.get("length", "m")
        ax.plot(r[:, i], r[:, j], label=f"{body} ({point})")
        ax.plot(r[:1, i], r[:1, j], "o", label="start")
        ax.set_xlabel(f"{plane[0]} [{unit}]")
        ax.set_ylabel(f"{plane[1]} [{unit}]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(f"{self.name}: path of {body}")
        ax.legend()
        ax.grid(True)
        return ax

    def plot_phase(self, coordinate: str, ax: Any = None) -> Any:
        """Phase portrait ``ẏ_i`` over ``y_i``; returns the Axes."""
        import matplotlib.pyplot as plt

        if coordinate not in self.coordinate_names:
            raise EvaluationError(f'unknown coordinate "{coordinate}"; coordinates are '
                                  f"{self.coordinate_names}")
        if ax is None:
            _, ax = plt.subplots()
        i = self.coordinate_names.index(coordinate)
        ax.plot(self.y[:, i], self.yd[:, i])
        ax.plot(self.y[:1, i], self.yd[:1, i], "o", label="start")
        ax.set_xlabel(self._label(coordinate, 0))
        ax.set_ylabel(self._label(coordinate, 1))
        ax.set_title(f"{self.name}: phase portrait of {coordinate}")
        ax.legend()
        ax.grid(True)
        return ax


def _load_csv(path: Path, system: System | None) -> Results:
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

    def block(keys: list[str]) -> np.ndarray:
        return data[:, [col[k] for k in keys]] if keys else np.zeros((len(data), 0))

    energies = {}
    if "T" in col and system is None:
        energies = {"T": data[:, col["T"]], "V": data[:, col["V"]], "conservative": False,
                    "nonconservative": ()}
    return Results(system, data[:, 0], block(names), block([f"{n}_d" for n in names]),
                   block([f"{n}_dd" for n in names]), block(inputs), data[:, col["W"]],
                   json.loads(meta["parameters"]), method=meta.get("method", ""),
                   rtol=float(meta.get("rtol", "nan")), status=meta.get("status", ""),
                   message=meta.get("message", ""), nfev=int(meta.get("nfev", 0)),
                   nsteps=int(meta.get("nsteps", 0)),
                   wall_time=float(meta.get("wall_time", 0.0)), coordinate_names=names,
                   input_names=inputs, units=json.loads(meta["units"]), energies=energies,
                   name=meta.get("system", ""))


# --- incremental writing ------------------------------------------------------------------------
def open_incremental(path: str | Path, system: System) -> Any:
    """Create a results file that :func:`append_incremental` fills while a run goes."""
    import h5py

    n = 2 * system.f + 1
    h = h5py.File(path, "w")
    h.attrs["format"] = FORMAT
    h.attrs["version"] = VERSION
    h.attrs["system"] = system.name
    h.attrs["status"] = "running"
    h.attrs["message"] = "run in progress (or killed): /partial holds the accepted steps"
    h.attrs["coordinates"] = json.dumps(system.coordinate_names)
    h.attrs["inputs"] = json.dumps(system.input_names)
    h.attrs["parameters"] = json.dumps(system.parameter_values)
    h.attrs["units"] = json.dumps(dict(system.units))
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
    dt, dx = h["partial/t"], h["partial/x"]
    m = dt.shape[0]
    dt.resize((m + len(t),))
    dx.resize((m + len(t), dx.shape[1]))
    dt[m:] = t
    dx[m:] = x
    h.flush()
