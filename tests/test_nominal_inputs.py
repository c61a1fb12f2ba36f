"""Nominal motions with nominal inputs, and the warning when a claimed equilibrium or steady
motion is not a solution of the equations of motion (h ≠ 0) — issue 17, item 9."""

import warnings

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import main
from jourdain.io import capabilities, load_model
from jourdain.models import double_pendulum
from jourdain.stages.linearization import NOMINAL_RTOL, NominalMotionWarning

D, J, OMEGA = 0.4, 0.05, 3.0


def driven_rotor() -> jd.System:
    """A disc turning about z on a damped bearing (damping d), driven by a motor torque tau."""
    phi, d, Jz, tau, Omega = jd.symbols("phi d Jz tau Omega")
    disc = jd.Body("disc", "world", jd.Revolute("bearing", phi, "z"), mass=1.0,
                   inertia=(Jz, Jz, Jz))
    return jd.System([phi], [disc],
                     [jd.RotationalSpringDamper("bearing_damper", phi, damping=d),
                      jd.GeneralizedForce("motor", phi, tau)],
                     parameters={"d": D, "Jz": J, "Omega": OMEGA}, inputs=[tau],
                     name="driven rotor")


def test_steady_rotation_needs_the_motor_torque():
    """Turning at Ω against the damping needs τ = d·Ω. Without it the old code reported a
    'marginally stable' steady rotation with h = −d·Ω and nothing else; now linearize and the
    verdict warn and name the torque that holds it, and with inputs= the nominal is a solution."""
    s = driven_rotor()
    Omega = jd.symbols("Omega")
    with pytest.warns(NominalMotionWarning, match=r'"tau": 1\.2'):
        lin = s.linearize({"phi": Omega * jd.t})
    check = lin.check_nominal()
    assert check.kind == "steady motion" and not check.is_solution
    np.testing.assert_allclose(check.h, [-D * OMEGA], rtol=1e-14)
    assert check.holding_inputs == pytest.approx({"tau": D * OMEGA}, rel=1e-14)
    with pytest.warns(NominalMotionWarning):
        st = jd.stability(lin, cyclic=())
    assert st.verdict == jd.analysis.MARGINALLY_STABLE  # the linear system itself
    with pytest.warns(NominalMotionWarning):
        routh = jd.stability(lin)  # phi is cyclic: its rate returns to Omega (λ = −d/J)
    assert routh.verdict == jd.analysis.ASYMPTOTICALLY_STABLE and routh.cyclic == ("phi",)
    assert st.nominal_is_solution is False and "WARNING" in st.reason and "tau" in st.reason

    d = jd.symbols("d")
    with warnings.catch_warnings():
        warnings.simplefilter("error", NominalMotionWarning)
        held = s.linearize({"phi": Omega * jd.t}, inputs={"tau": d * Omega})
        st = jd.stability(held)
        # the same as inputs inside the nominal mapping, and in the numeric path
        same = s.linearize({"phi": Omega * jd.t, "tau": d * Omega})
        num = jd.linearize_numeric(s, {"phi": Omega * jd.t}, inputs={"tau": d * Omega})
    assert held.check_nominal().is_solution and st.nominal_is_solution is True
    assert "WARNING" not in st.reason
    np.testing.assert_array_equal(held.evaluate()["h"], [0.0])
    np.testing.assert_array_equal(same.evaluate()["h"], [0.0])
    assert num.check_nominal().is_solution
    assert held.u_s.entries() == [d * Omega]
    with pytest.warns(NominalMotionWarning):
        jd.linearize_numeric(s, {"phi": Omega * jd.t})


def test_bad_nominal_inputs_are_reported():
    s = driven_rotor()
    with pytest.raises(jd.ModelError, match="not inputs of the system"):
        s.linearize({"phi": 0}, inputs={"phi": 1.0})
    with pytest.raises(jd.ModelError, match='"tau" is given twice'):
        s.linearize({"phi": 0, "tau": 0}, inputs={"tau": 1.0})
    with pytest.raises(jd.ModelError, match="unknown symbol"):
        s.linearize({"phi": 0}, inputs={"tau": jd.symbols("w")})


def test_residual_is_judged_against_the_forces_at_work():
    """Upright, q = −m g l sin φ is round-off of m g l: the scale comes from the forces and
    lever arms (‖J̄_i‖·‖q̄^e‖), so π in floating point passes and 3.14159 does not."""
    s = double_pendulum()
    with warnings.catch_warnings():
        warnings.simplefilter("error", NominalMotionWarning)
        for up in (jd.pi, np.pi):
            lin = s.linearize({"phi1": up, "phi2": 0})
            check = lin.check_nominal()
            assert check.is_solution and check.relative < 1e3 * np.finfo(float).eps
    with pytest.warns(NominalMotionWarning, match="find_equilibrium"):
        lin = s.linearize({"phi1": 3.14159, "phi2": 0})
    check = lin.check_nominal()
    # sin(π − 3.14159) ≈ 2.65e-6 of the gravity moments
    assert 1e-6 < check.relative < 1e-5 and check.relative > NOMINAL_RTOL
    # an equilibrium found numerically is a solution to its own tolerance
    eq = jd.find_equilibrium(s, {"phi1": 3.0, "phi2": 0.1})
    with warnings.catch_warnings():
        warnings.simplefilter("error", NominalMotionWarning)
        assert s.linearize(eq).check_nominal().is_solution


def test_reference_trajectories_are_not_claimed_solutions():
    """h of a trajectory with ÿ_s ≠ 0 is its feed-forward: no warning."""
    s = double_pendulum()
    with warnings.catch_warnings():
        warnings.simplefilter("error", NominalMotionWarning)
        lin = s.linearize({"phi1": jd.sin(jd.t), "phi2": 0})
    assert lin.check_nominal(0.3).kind == "nominal motion"
    assert not lin.check_nominal(0.3).is_solution


MODEL = """
[model]
name = "driven rotor"

[coordinates]
phi = "rad"

[parameters]
d = { value = 0.4, unit = "N*m*s/rad" }
Jz = { value = 0.05, unit = "kg*m^2" }
Omega = { value = 3.0, unit = "rad/s" }

[inputs]
tau = "N*m"

[bodies.disc]
parent = "world"
mass = 1.0
inertia = ["Jz", "Jz", "Jz"]
joint = { type = "revolute", name = "bearing", coordinate = "phi", axis = "z" }

[forces.damper]
type = "generalized"
coordinate = "phi"
value = "-d*phi_d"

[forces.motor]
type = "generalized"
coordinate = "phi"
value = "tau"

[nominal.driven]
description = "turning at Omega, the motor holding it against the damping"
y = { phi = "Omega*t" }
inputs = { tau = "d*Omega" }

[nominal.coasting]
description = "turning at Omega with the motor off (not a solution)"
y = { phi = "Omega*t" }
"""


@pytest.fixture
def model_file(tmp_path):
    path = tmp_path / "driven_rotor.toml"
    path.write_text(MODEL)
    return path


def test_model_file_nominal_inputs(model_file, capsys):
    model = load_model(model_file)
    driven, coasting = model.nominal
    assert [n for n, _ in driven.inputs] == ["tau"] and coasting.inputs == ()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the CLI layer keeps the warning in its text
        res = capabilities.linear_analysis(model, "driven")
        bad = capabilities.linear_analysis(model, "coasting")
    assert res["nominal_check"].is_solution and res["stability"].nominal_is_solution
    np.testing.assert_array_equal(res["numbers"]["h"], [0.0])
    assert not bad["nominal_check"].is_solution
    assert capabilities.jsonable(bad)["nominal_is_solution"] is False
    assert capabilities.jsonable(res)["nominal_inputs"] == {"tau": "d*Omega"}

    assert main(["linearize", str(model_file), "--about", "driven"]) == 0
    out = capsys.readouterr().out
    assert "u_s(t) = tau = d*Omega" in out and "WARNING" not in out
    assert main(["linearize", str(model_file), "--about", "coasting"]) == 0
    out = capsys.readouterr().out
    assert out.count("WARNING") == 2  # under the header and in the stability verdict
    assert '"tau": 1.2' in out


def test_model_file_rejects_unknown_nominal_input(model_file):
    text = model_file.read_text().replace('inputs = { tau = "d*Omega" }',
                                          'inputs = { torque = "d*Omega" }')
    model_file.write_text(text)
    with pytest.raises(jd.ModelFileError, match='"torque" is not a declared input'):
        load_model(model_file)


def test_eval_about_any_state_does_not_warn(capsys):
    """jourdain eval linearizes about the state it is given; h = M·ÿ there is expected."""
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "double_pendulum.toml"
    with warnings.catch_warnings():
        warnings.simplefilter("error", NominalMotionWarning)
        assert main(["eval", str(path), "--at", "phi1=0.3"]) == 0
    capsys.readouterr()
