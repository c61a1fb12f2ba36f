"""LQR for the double pendulum on a cart, designed with python-control on jourdain's
linearization and closed in a jourdain simulation (docs/control.md).

    pip install "jourdain[control]"
    python examples/lqr_cart_pendulum.py            # prints the design and the comparison
    python examples/lqr_cart_pendulum.py --plot     # and writes lqr_cart_pendulum.png
"""

from __future__ import annotations

import sys

import control
import numpy as np

import jourdain as jd
from jourdain.models import n_link_pendulum_on_cart


def main(plot: bool = False) -> None:
    cart = n_link_pendulum_on_cart(2)  # cart q0 (m), links q1, q2 (rad) from upright, force F (N)
    upright = {"q0": 0, "q1": 0, "q2": 0}
    lin = cart.linearize(upright)
    plant = jd.to_control(lin)  # all six states as outputs
    print(plant)
    print("open-loop eigenvalues:", np.round(np.linalg.eigvals(plant.A), 4))

    K, _, E = control.lqr(plant, np.diag([1.0, 10.0, 10.0, 0.1, 0.1, 0.1]), np.eye(1))
    print("LQR gain K:", np.round(K, 4))
    print("closed-loop eigenvalues:", np.round(E, 4))

    law = jd.state_feedback(cart, K, lin)  # F = −K·x, compiled into the integration loop
    x0 = np.array([0.0, 0.05, -0.02, 0.0, 0.0, 0.0])
    t = np.linspace(0.0, 8.0, 401)
    res = cart.simulate((0.0, 8.0), x0[:3], x0[3:], inputs=law, t_eval=t)
    closed = control.ss(plant.A - plant.B @ K, plant.B, np.eye(6), np.zeros((6, 1)))
    linear = control.initial_response(closed, T=t, X0=x0).states.T
    sim = np.hstack([res.y, res.yd])
    dev = np.abs(sim - linear).max() / np.abs(linear).max()
    print(f"nonlinear closed loop against the linear prediction: {dev:.2e} of the motion "
          f"(initial tilt {x0[1]} rad)")
    print("state at t = 8 s: " + ", ".join(f"{n} = {v:.3g}" for n, v in
                                           zip(plant.state_labels, sim[-1], strict=True)))

    if plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axs = plt.subplots(2, 1, figsize=(7, 6), sharex=True, layout="constrained")
        res.plot("y", ax=axs[0])
        for i in range(3):
            axs[0].plot(t, linear[:, i], "k:", linewidth=0.8)
        res.plot("u", ax=axs[1])
        fig.savefig("lqr_cart_pendulum.png", dpi=120)
        print("wrote lqr_cart_pendulum.png (dotted: the linear closed loop)")


if __name__ == "__main__":
    main(plot="--plot" in sys.argv[1:])
