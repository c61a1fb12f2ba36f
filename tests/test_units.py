"""Units everywhere (jourdain.units): units of coordinates derived from the joint kinds, of
rates, accelerations, inputs, reaction components and energies; as they appear on the axes of
the figures (matplotlib's get_xlabel/get_ylabel), in the CSV and HDF5 results and in the JSON of
``jourdain eval`` and of the report."""

import json

import matplotlib
import numpy as np
import pytest

import jourdain as jd
from jourdain import units
from jourdain.io import load_model
from jourdain.models import n_link_pendulum_on_cart

matplotlib.use("Agg")


@pytest.fixture(autouse=True)
def _close_figures():
    """Each test's figures are closed after it (pyplot keeps them otherwise)."""
    yield
    import matplotlib.pyplot as plt

    plt.close("all")

# the angle of every rotation step and the distance of every translation step of each kind
JOINT_KINDS = {
    "revolute": (lambda c: jd.Revolute("j", c[0], "z"), ["rad"]),
    "prismatic": (lambda c: jd.Prismatic("j", c[0], "x"), ["m"]),
    "cylindrical": (lambda c: jd.Cylindrical("j", c, "z"), ["rad", "m"]),
    "universal": (lambda c: jd.Universal("j", c), ["rad", "rad"]),
    "spherical": (lambda c: jd.Spherical("j", c), ["rad"] * 3),
    "planar": (lambda c: jd.Planar("j", c), ["m", "m", "rad"]),
    "free": (lambda c: jd.Free("j", c), ["m"] * 3 + ["rad"] * 3),
}


def _one_body(joint, coords, forces=(), units_=None, parameters=None):
    body = jd.Body("b", "world", joint, mass=1.0, inertia=jd.box(1.0, 0.1, 0.2, 0.3))
    return jd.System(coords, [body], list(forces), parameters=parameters or {}, units=units_,
                     name="one body")


@pytest.mark.parametrize("kind", sorted(JOINT_KINDS))
def test_coordinate_units_from_the_joint_kind(kind):
    make, expected = JOINT_KINDS[kind]
    coords = jd.symbols(" ".join(f"c{i}" for i in range(len(expected))))
    coords = list(coords) if isinstance(coords, tuple) else [coords]
    s = _one_body(make(coords), coords)
    got = units.coordinate_units(s)
    assert list(got.values()) == expected
    for c, u in got.items():  # rates and accelerations per second and per second squared
        assert units.unit_of(f"{c}_d", units.model_units(s), s.coordinate_names) == f"{u}/s"
        assert units.unit_of(f"{c}_dd", units.model_units(s), s.coordinate_names) == f"{u}/s^2"


def test_declared_units_win_and_unknown_units_stay_unknown():
    q, r, l = jd.symbols("q r l")
    # a translation by l·q: q is dimensionless (l a length), not a length
    joint = jd.General("j", [jd.Trans("x", l * q), jd.Rot("z", r)], coordinates=[q, r])
    s = _one_body(joint, [q, r], parameters={"l": 2.0})
    assert units.coordinate_units(s) == {"q": "", "r": "rad"}
    s = _one_body(joint, [q, r], parameters={"l": 2.0}, units_={"q": "1", "r": "deg"})
    assert units.coordinate_units(s) == {"q": "1", "r": "deg"}
    assert units.axis_label("q", "1") == "q"  # dimensionless: the name alone
    # a model in mm and g: lengths, forces, torques and energies follow
    x = jd.symbols("x")
    F = jd.symbols("F")
    s = jd.System([x], [jd.Body("b", "world", jd.Prismatic("p", x, "x"), mass=jd.symbols("m"),
                                inertia=jd.point_mass())],
                  [jd.Force("push", "b", (F, 0, 0)), jd.Torque("twist", "b", (0, 0, 3 * F))],
                  parameters={"m": 5.0}, inputs=[F], units={"m": "g", "a": "mm"})
    assert units.coordinate_units(s) == {"x": "mm"}
    # F enters a force and a torque: no single unit
    assert units.input_units(s) == {"F": ""}
    assert units.force_unit(dict(s.units)) == "g mm/s^2"
    assert units.torque_unit(dict(s.units)) == units.energy_unit(dict(s.units)) == "g mm^2/s^2"


def test_input_units_from_the_force_elements():
    s = n_link_pendulum_on_cart(2)  # F: the horizontal force on the cart
    assert units.input_units(s) == {"F": "N"}
    phi, tau, k = jd.symbols("phi tau k")
    joint = jd.Revolute("j", phi, "z")
    for fe, expected in ((jd.Torque("motor", "b", (0, 0, tau)), "N m"),
                         (jd.GeneralizedForce("motor", phi, -2 * tau), "N m"),
                         (jd.GeneralizedForce("motor", phi, k * tau), "")):
        s = jd.System([phi], [jd.Body("b", "world", joint, mass=1.0,
                                      inertia=jd.box(1.0, 0.1, 0.2, 0.3))], [fe],
                      parameters={"k": 2.0}, inputs=[tau])
        assert units.input_units(s) == {"tau": expected}, fe


def test_axis_labels():
    assert units.axis_label("phi1", "rad") == "phi1 / rad"
    assert units.axis_label("phi1_d", "rad/s") == "phi1_d / (rad/s)"
    assert units.axis_label("M_z", "N m") == "M_z / (N m)"
    assert units.axis_label("F_y", "N") == "F_y / N"
    assert units.axis_label("x", "") == "x"
    assert units.per_time("N m", 1) == "(N m)/s"
    assert units.shared_label([("q0", "m"), ("q1", "rad"), ("q2", "rad")], "y") == (
        "q0 / m; q1, q2 / rad")
    assert units.shared_label([(f"q{i}", "rad") for i in range(5)], "y") == "y / rad"


@pytest.fixture(scope="module")
def cart_run():
    s = n_link_pendulum_on_cart(1)  # q0: prismatic (m), q1: revolute (rad), F: force (N)
    return s, s.simulate((0, 0.5), [0.0, 0.3], [0.1, 0.0], inputs={"F": 0.5},
                         t_eval=np.linspace(0, 0.5, 11))


def test_figure_labels_carry_the_derived_units(cart_run):
    _, res = cart_run
    expected = {"q0": "m", "q1": "rad"}
    for c, u in expected.items():
        ax = res.plot("y", coordinates=[c])
        assert ax.get_ylabel() == f"{c} / {u}" and ax.get_xlabel() == "t / s"
        assert res.plot("yd", coordinates=[c]).get_ylabel() == f"{c}_d / ({u}/s)"
        assert res.plot("ydd", coordinates=[c]).get_ylabel() == f"{c}_dd / ({u}/s^2)"
        ax = res.plot_phase(c)
        assert (ax.get_xlabel(), ax.get_ylabel()) == (f"{c} / {u}", f"{c}_d / ({u}/s)")
    ax = res.plot("y")
    assert ax.get_ylabel() == "q0 / m; q1 / rad"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["q0 / m", "q1 / rad"]
    assert res.plot("u").get_ylabel() == "F / N"
    assert res.plot("energy").get_ylabel() == "energy / J"
    ax = res.plot("g")
    assert ax.get_ylabel() == "forces / N; torques / (N m)"
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == [units.axis_label(n, "N m" if ".T_" in n else "N") for n in res.g_names]
    assert "hinge1.T_x / (N m)" in legend and "slider.F_y / N" in legend
    ax = res.plot_path("link1")
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x / m", "y / m")


def test_csv_and_hdf5_headers_carry_the_units(cart_run, tmp_path):
    import h5py

    _, res = cart_run
    path = res.save(tmp_path / "cart.csv")
    meta = {}
    for line in path.read_text().splitlines():
        if not line.startswith("# "):
            cols = line.split(",")
            break
        k, _, v = line[2:].partition(": ")
        meta[k] = v
    col_units = dict(zip(cols, json.loads(meta["column_units"]), strict=True))
    assert col_units == {"t": "s", "q0": "m", "q1": "rad", "q0_d": "m/s", "q1_d": "rad/s",
                         "q0_dd": "m/s^2", "q1_dd": "rad/s^2", "F": "N", "W": "J", "T": "J",
                         "V": "J"}
    assert json.loads(meta["units"])["q1"] == "rad"
    back = jd.Results.load(path)  # without the system: the units come from the file
    assert back.label("q0_d") == "q0_d / (m/s)" and back.unit("F") == "N"
    path = res.save(tmp_path / "cart.h5")
    with h5py.File(path) as h:
        assert json.loads(h["y"].attrs["units"]) == ["m", "rad"]
        assert json.loads(h["yd"].attrs["units"]) == ["m/s", "rad/s"]
        assert json.loads(h["ydd"].attrs["units"]) == ["m/s^2", "rad/s^2"]
        assert json.loads(h["u"].attrs["units"]) == ["N"]
        assert [h[k].attrs["units"] for k in ("t", "W", "T", "V")] == ["s", "J", "J", "J"]


CART_MODEL = """
[model]
name = "cart and pendulum"
[coordinates]
x = { description = "cart position, unit from the prismatic joint" }
phi = { description = "pendulum angle, unit from the revolute joint" }
[parameters]
m = { value = 1.0, unit = "kg" }
l = { value = 0.5, unit = "m" }
g = 9.81
[inputs]
F = { description = "force on the cart, unit from the force element" }
[bodies.cart]
parent = "world"
mass = "m"
inertia = { box = { a = 0.3, b = 0.1, c = 0.2 } }
joint = { type = "prismatic", name = "rail", coordinate = "x", axis = "x" }
[bodies.bob]
parent = "cart"
mass = "m"
com = [0, "-l", 0]
inertia = "point"
joint = { type = "revolute", name = "pivot", coordinate = "phi", axis = "z" }
[forces.gravity]
type = "gravity"
vector = [0, "-g", 0]
[forces.motor]
type = "force"
body = "cart"
vector = ["F", 0, 0]
[simulation]
t_end = 0.3
samples = 7
y0 = { phi = 0.2 }
inputs = { F = 1.0 }
"""


def test_report_figures_and_json_carry_the_units(tmp_path, monkeypatch):
    from jourdain.io import report
    from jourdain.io.report import figures  # H8: the plots' SVG writer lives here

    labels = []
    svg = figures.svg

    def recording(fig):  # the labels of every figure the report draws, then the SVG as before
        labels.extend((ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes)
        return svg(fig)

    monkeypatch.setattr(figures, "svg", recording)
    path = tmp_path / "cart.toml"
    path.write_text(CART_MODEL)
    model = load_model(path)
    report.write_report(model, tmp_path / "out")
    assert ("t / s", "x / m; phi / rad") in labels
    assert ("t / s", "x_d / (m/s); phi_d / (rad/s)") in labels
    assert ("t / s", "energy / J") in labels
    assert ("t / s", "forces / N; torques / (N m)") in labels
    html = (tmp_path / "out" / "report.html").read_text()
    for name, unit in (("x", "m"), ("phi", "rad"), ("F", "N")):  # tables of the model
        assert f"<td>{name}</td><td>{unit}</td>" in html
    values = json.loads((tmp_path / "out" / "values.json").read_text())
    u = values["units"]
    assert (u["t"], u["y"], u["yd"], u["inputs"]) == ("s", ["m", "rad"], ["m/s", "rad/s"],
                                                     {"F": "N"})
    # generalized forces: a force on the length x, a torque on the angle phi
    assert u["k"] == u["q"] == ["N", "N m"]
    assert u["g"] == [units.reaction_unit(n, {}) for n in values["g_names"]]
    assert {"N", "N m"} == set(u["g"])
    header = (tmp_path / "out" / "simulation.csv").read_text().splitlines()
    meta = dict(ln[2:].split(": ", 1) for ln in header if ln.startswith("# "))
    assert json.loads(meta["column_units"])[:3] == ["s", "m", "rad"]
