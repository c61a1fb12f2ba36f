"""Every public function and command that takes a system, run on a closed mechanism (issue 32,
"walk every entry point"): each gives the closed system's result, checked against a reference
computed here from the tree's own numbers, or raises :class:`ClosedSystemError` naming the
capability. None may use the open tree silently. The table of outcomes is in
docs/closed-loops.md; :data:`OUTCOME` classifies every function of ``jourdain.__all__`` so that
a new one fails here until it is classified."""

from __future__ import annotations

import inspect
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.errors import ClosedSystemError
from jourdain.models import four_bar
from jourdain.numeric import evaluate as tree_evaluate
from tests.tolerance import solve_tol

ROOT = Path(__file__).resolve().parents[1]
Y0, YD0 = [0.5, 0.8, 1.9], [1.0, 0.0, 0.0]

#: every function of jourdain.__all__: "builder" (takes no system: model building, files),
#: "closed" (gives the closed system's result), "refused" (ClosedSystemError), "stage" (a
#: stage function of the tree's symbolic stages: the closed system's are its methods)
OUTCOME = {
    **dict.fromkeys(["symbols", "box", "cylinder", "disc", "point_mass", "rod", "Revolute",
                     "Prismatic", "Cylindrical", "Universal", "Spherical", "Planar", "Free",
                     "Fixed", "General", "RotationalSpringDamper", "rate", "acceleration",
                     "position", "velocity", "point_acceleration", "angular_velocity",
                     "relative_position", "relative_velocity", "distance", "distance_rate",
                     "load_model", "load_urdf", "planar_inertia"], "builder"),
    **dict.fromkeys(["newton_euler", "projection", "reactions", "linearization",
                     "linearization_general", "energy", "constraints"], "stage"),
    **dict.fromkeys(["simulate", "state_space", "modes", "stability", "frequency_response",
                     "to_control", "view", "derivatives"], "closed"),
    **dict.fromkeys(["kinematics", "evaluate_reactions", "joint_reactions", "joint_wrenches",
                     "linearize_numeric", "sweep", "stability_boundary", "floquet",
                     "cyclic_coordinates", "find_equilibrium", "find_equilibria",
                     "state_feedback", "to_casadi", "mode_motion"], "refused"),
}


@pytest.fixture(scope="module")
def closed() -> tuple[jd.System, jd.Results, object]:
    system = four_bar()
    return system, system.simulate((0.0, 0.3), Y0, YD0), system.linearize({"theta1": 0.5})


def test_every_public_function_is_classified() -> None:
    funcs = [n for n in jd.__all__ if inspect.isfunction(getattr(jd, n))]
    assert sorted(set(funcs) - set(OUTCOME)) == []
    assert sorted(set(OUTCOME) - set(funcs)) == []


def test_refused_functions_name_the_closing_joints(closed) -> None:  # noqa: ANN001
    system, res, lin = closed
    calls = {
        "kinematics": lambda: jd.kinematics(system),
        "evaluate_reactions": lambda: jd.evaluate_reactions(system, Y0, YD0),
        "joint_reactions": lambda: jd.joint_reactions(system, "ground1", Y0, YD0),
        "joint_wrenches": lambda: jd.joint_wrenches(system, np.zeros(15), Y0),
        "linearize_numeric": lambda: jd.linearize_numeric(system, {"theta1": 0.5}),
        "sweep": lambda: jd.sweep(lin, "m1", [1.0, 2.0]),
        "stability_boundary": lambda: jd.stability_boundary(lin, "m1", 0.5, 2.0),
        "floquet": lambda: jd.floquet(lin, 1.0),
        "cyclic_coordinates": lambda: jd.cyclic_coordinates(system),
        "find_equilibrium": lambda: jd.find_equilibrium(system, Y0),
        "find_equilibria": lambda: jd.find_equilibria(system, [Y0]),
        "state_feedback": lambda: jd.state_feedback(system, np.zeros((0, 2)),
                                                    {"theta1": 0.5}),
        "to_casadi": lambda: jd.to_casadi(system),
        "mode_motion": lambda: jd.mode_motion(lin, 1),
    }
    assert set(calls) == {k for k, v in OUTCOME.items() if v == "refused"}
    for name, call in calls.items():
        with pytest.raises(ClosedSystemError, match="closure") as info:
            call()
        assert info.value.capability, name  # the error names what cannot be done


def test_symbolic_stages_are_the_trees_by_name_only() -> None:
    system = four_bar()
    for method in (system.newton_euler, system.equations_of_motion, system.reactions):
        with pytest.raises(ClosedSystemError, match="closure"):
            method()
    # the stage functions take the stage before; the closed system's kinematics are its
    # tree's (visibly: their system is the tree), its own rows are its constraint stage
    kin = system.kinematics()
    assert kin.system == system.tree and not kin.system.closing
    assert system.constraints().labels == ["closure.Fx", "closure.Fy"]


def test_closed_results_against_the_trees_numbers(closed) -> None:  # noqa: ANN001
    """evaluate, simulate, linearize, state_space, stability, modes, frequency_response,
    view: the closed system's numbers, checked against the projection done here by hand from
    the tree's M, k, q and a velocity map from Φ_y (independent of jourdain.loops)."""
    system, res, lin = closed
    out = system.evaluate(Y0, YD0)
    tree = tree_evaluate(system.tree, out["y"], out["yd"])
    Py = out["Phi_y"]
    # velocity map: the null space of Φ_y with the independent coordinate theta1 as parameter
    dep = [1, 2]
    L = np.zeros((3, 1))
    L[0, 0] = 1.0
    L[dep, 0] = -np.linalg.solve(Py[:, dep], Py[:, [0]])[:, 0]
    M = L.T @ tree["M"] @ L
    tol = solve_tol(Py[:, dep], float(np.max(np.abs(tree["M"])))) * 10
    assert np.max(np.abs(out["M"] - M)) <= tol
    assert np.max(np.abs(out["q"] - L.T @ tree["q"])) <= tol * (1 + np.max(np.abs(tree["q"])))
    # simulate: the one Results type, on the manifold, the tree coordinates
    assert isinstance(res, jd.Results) and res.y.shape[1] == 3
    assert res.closure_residual[0] <= 1e-9
    assert isinstance(jd.simulate(system, (0.0, 0.3), Y0, YD0, t_eval=res.t), jd.Results)
    # linearization in the independent coordinate: state space, stability, modes
    ss = jd.state_space(lin)
    assert ss.coordinate_names == ("theta1",) and ss.A.shape == (2, 2)
    assert np.allclose(np.sort(np.linalg.eigvals(ss.A).real),
                       np.sort(np.asarray(lin.eigenvalues).real))
    assert jd.stability(lin).verdict
    assert len(jd.modes(lin).eigenvalues) == 2
    w = np.array([1.0, 2.0])
    fr = jd.frequency_response(lin, w, excitation="h")
    ref = 1.0 / (lin.Q[0, 0] - w ** 2 * lin.M_tilde[0, 0] + 1j * w * lin.P[0, 0])
    assert fr.coordinate_names == ("theta1",)
    assert np.allclose(fr.response[:, 0, 0], ref, rtol=1e3 * np.finfo(float).eps * max(
        1.0, float(np.max(np.abs(ref))) * abs(lin.Q[0, 0])))
    # the viewer draws the closed mechanism (its frames from the tree's kinematics at y)
    assert jd.view(res) is not None


#: every command of the command line on the closed four-bar: its arguments and what the
#: output must show of the closed system (not of the open tree)
COMMANDS = {
    "check": ([], ["closure", "1 by the rank 2 of Φ"]),
    "eom": ([], ["Φ_y", "M_tree", "λ"]),
    "eval": (["--json"], ['"closure_residual"', '"independent"']),
    "reactions": (["--json"], ['"closure.Fx"']),
    "linearize": (["--json"], ['"independent"']),
    "simulate": (["--t-end", "0.2"], []),
    "run": (["--t-end", "0.2"], ["report:"]),
    "fmu": (["--sources-only"], []),
    "study": ([], []),
}


def test_every_command_on_a_closed_model(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    """Each command gives the closed system's output (its markers above; the numbers are
    checked against references in tests/test_closed_cli.py, test_closed_report.py,
    test_fmu_closed.py and test_study_closed.py) and exits 0; the table covers every
    command the parser has."""
    import json

    from jourdain.cli import main
    from jourdain.cli.parser import build_parser

    subs = next(a for a in build_parser()._actions if a.dest == "command")
    assert set(subs.choices) == set(COMMANDS)  # type: ignore[union-attr]
    model = str(ROOT / "examples" / "four_bar.toml")
    for command, (extra, markers) in COMMANDS.items():
        argv = [command, model, *extra]
        if command in ("simulate",):
            argv += ["--out", str(tmp_path / "fb.csv")]
        elif command == "run":
            argv += ["--out", str(tmp_path / "report")]
        elif command == "fmu":
            argv += ["--out", str(tmp_path / "fb.fmu")]
        elif command == "study":
            argv = [command, "--spec", str(ROOT / "examples" / "studies" /
                                           "four_bar_stability_map.toml"),
                    "--out", str(tmp_path / "map.nc")]
        code = main(argv)
        out, err = capsys.readouterr()
        assert code == 0, (command, err)
        for marker in markers:
            assert marker in out, (command, marker)
        if command == "eval":  # the closed system's M: 1×1 in theta1, not the tree's 3×3
            assert np.asarray(json.loads(out)["values"]["M"]).shape == (1, 1)
    sim = jd.Results.load(tmp_path / "fb.csv")
    assert sim.y.shape[1] == 3 and (tmp_path / "report" / "loops.json").is_file()
    assert (tmp_path / "fb.fmu").is_file() and (tmp_path / "map.nc").is_file()


def test_to_control_of_a_closed_linearization(closed) -> None:  # noqa: ANN001
    """python-control's state space of the closed linearization: the independent
    coordinate's states, and its poles are the linearization's eigenvalues."""
    control = pytest.importorskip("control")
    _, _, lin = closed
    sys_c = jd.to_control(lin)
    assert list(sys_c.state_labels) == ["theta1", "theta1_d"]
    poles = np.sort_complex(np.asarray(control.poles(sys_c), complex))
    ref = np.sort_complex(np.asarray(lin.eigenvalues, complex))
    assert np.max(np.abs(poles - ref)) <= 1e3 * np.finfo(float).eps * max(1.0, np.abs(ref).max())
