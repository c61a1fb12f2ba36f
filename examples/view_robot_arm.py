"""The 3-D view of a simulated motion (docs/viewer.md): the 6-joint robot arm of
robot_arm.toml falling from its initial pose under gravity, as one self-contained HTML page.

    python examples/view_robot_arm.py [out.html]

Open the page in a browser (offline, from file://): play, pause, drag the time slider, drag to
turn the view. In Jupyter, ``jd.view(res)`` as the last line of a cell shows the same page.
"""

import sys
from pathlib import Path

import jourdain as jd

HERE = Path(__file__).resolve().parent


def main(out: str = "robot_arm_view.html") -> None:
    model = jd.load_model(HERE / "robot_arm.toml")
    sim = model.simulation
    res = model.system.simulate((0.0, sim.t_end), sim.y0, sim.yd0)
    v = jd.view(res)  # equivalent boxes of the links' inertia, frames as triads
    v.save(out)
    print(f"{out}: {v!r}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
