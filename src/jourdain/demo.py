"""The default example: equations of motion of the double pendulum (run by ``make run``)."""

from __future__ import annotations

import sympy

from .models import double_pendulum


def main() -> None:
    system = double_pendulum()
    eom = system.equations_of_motion()
    print(system)
    print("\nM(y) ="), sympy.pprint(sympy.trigsimp(eom.M.sympy()), use_unicode=True)
    print("\nk(y, yd) ="), sympy.pprint(sympy.trigsimp(eom.k.sympy()), use_unicode=True)
    print("\nq(y, yd) ="), sympy.pprint(sympy.trigsimp(eom.q.sympy()), use_unicode=True)
    values = system.evaluate([0.3, -0.2], [1.0, 0.5])
    print("\nAt phi1 = 0.3, phi2 = -0.2, phi1_d = 1.0, phi2_d = 0.5 with the default parameters:")
    for name in ("M", "k", "q"):
        print(f"{name} =\n{values[name]}")


if __name__ == "__main__":
    main()
