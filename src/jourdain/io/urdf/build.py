"""The jourdain model of a parsed URDF robot: the tree walked depth-first in file order
(Pinocchio's order), one body per moving joint, fixed joints welded, the mass data merged
into parameters, actuator inputs and the descriptions of coordinates and parameters.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import symengine as se

from ...errors import ModelError
from ...model import (
    Body,
    Free,
    General,
    GeneralizedForce,
    Gravity,
    Planar,
    Prismatic,
    Revolute,
    Rot,
    RotationalSpringDamper,
    Trans,
)
from ...pipeline import System  # jourdain.System: the model with its stages (issue 16)
from ..modelfile import (
    NominalMotion,
    SimulationSettings,
)
from .geometry import _geometry
from .mass import _add_inertial, _Mass, _mass_below
from .model import (
    _AXIS_NAMES,
    MOVING,
    ROOT_COORDINATES,
    ROOT_JOINT,
    UrdfError,
    UrdfJoint,
    UrdfLink,
    UrdfModel,
)
from .source import _float, _float_or, _matrix, _Names, _pose, _Source


def _build(robot: Any, src: _Source, *, floating_base: bool, g: float, mimic: str,
           joint_damping: bool, actuated: bool) -> UrdfModel:
    path = src.path
    # --- the tree: unique names, every joint between declared links, one parent per link ---
    link_names = [lk.name for lk in robot.links]
    links = {}
    for lk in robot.links:
        if lk.name in links:
            raise UrdfError(f'link "{lk.name}" is declared twice', path,
                            src.line("link", lk.name))
        links[lk.name] = lk
    if not links:
        raise UrdfError("the robot has no link", path)
    parent_joint: dict[str, Any] = {}
    children: dict[str, list[Any]] = {n: [] for n in link_names}
    seen_joints: set[str] = set()
    for j in robot.joints:
        line = src.line("joint", j.name)
        if j.name in seen_joints:
            raise UrdfError(f'joint "{j.name}" is declared twice', path, line)
        seen_joints.add(j.name)
        for role, ln in (("parent", j.parent), ("child", j.child)):
            if ln not in links:
                raise UrdfError(f'joint "{j.name}": its {role} link "{ln}" is not declared '
                                "(no <link> of that name)", path, line)
        if j.type not in (*MOVING, "fixed"):
            raise UrdfError(f'joint "{j.name}": unknown joint type "{j.type}"; URDF types are '
                            "revolute, continuous, prismatic, fixed, floating, planar", path,
                            line)
        if j.child in parent_joint:
            raise UrdfError(
                f'joint "{j.name}": link "{j.child}" is already the child of joint '
                f'"{parent_joint[j.child].name}"; a link with two parents closes a kinematic '
                "loop, which is not supported (jourdain models trees)", path, line)
        if j.mimic is not None and mimic == "error":
            raise UrdfError(
                f'joint "{j.name}": a mimic joint (coupled to joint "{j.mimic.joint}"), refused '
                'as asked (mimic="error"); load_urdf(..., mimic="coupled") (the default) '
                "couples it, \"independent\" reads it as an ordinary joint with its own "
                "coordinate", path, src.line("mimic", j.name) or line)
        parent_joint[j.child] = j
        children[j.parent].append(j)
    roots = [n for n in link_names if n not in parent_joint]
    if len(roots) != 1:
        if not roots:
            raise UrdfError("every link is the child of a joint: the joints form a loop "
                            "(no root link)", path)
        raise UrdfError(f"the links do not form one tree: {len(roots)} root links ("
                        + ", ".join(f'"{r}"' for r in roots) + "); connect them by joints",
                        path, src.line("link", roots[1]))
    root = roots[0]

    # --- walk the tree depth-first (children in file order): bodies, joints, mass data ---
    body_names, joint_names = _Names("link"), _Names("joint")
    body_of: dict[str, str] = {}          # link -> jourdain body ("world" for a fixed base)
    pose_of: dict[str, np.ndarray] = {}   # link -> pose in its body's frame
    mass: dict[str, _Mass] = {}
    order: list[str] = []                 # jourdain bodies, parents first
    body_spec: dict[str, dict] = {}       # body -> parent, joint
    coords: list[str] = []
    coord_units: dict[str, str] = {}
    info: dict[str, UrdfJoint] = {}
    inputs: list[str] = []
    forces: list[Any] = []
    damping: dict[str, float] = {}        # parameter d_<coordinate> -> <dynamics damping>

    if floating_base:
        b = body_names(root)
        body_of[root], pose_of[root] = b, np.eye(4)
        mass[b] = _Mass()
        order.append(b)
        coords.extend(ROOT_COORDINATES)
        coord_units.update({c: "m" if k < 3 else "rad" for k, c in enumerate(ROOT_COORDINATES)})
        body_spec[b] = {"parent": "world", "joint": Free(ROOT_JOINT, _symbols(ROOT_COORDINATES), "zyx")}
    else:
        body_of[root], pose_of[root] = "world", np.eye(4)

    def visit(ln: str) -> None:
        """The link's own mass data into its body; its joints next on the stack (depth-first,
        children in file order, as Pinocchio adds them)."""
        if body_of[ln] != "world":
            _add_inertial(mass[body_of[ln]], links[ln], pose_of[ln], src)
        stack.extend(reversed(children[ln]))

    stack: list[Any] = []
    visit(root)
    while stack:
        j = stack.pop()
        ln = j.parent
        b = body_of[ln]
        jline = src.line("joint", j.name)
        origin = _matrix(j.origin, f'joint "{j.name}" <origin>', path, jline)
        X = pose_of[ln] @ origin  # joint frame in the parent body's frame
        axis = _axis(j, path, jline)
        common = {"name": j.name, "type": j.type, "parent": j.parent, "child": j.child,
                  "axis": tuple(float(a) for a in axis), "origin": _pose(origin),
                  **_limits(j, path, jline)}
        if j.mimic is not None:
            common["mimic"] = (str(j.mimic.joint),
                               _float_or(j.mimic.multiplier, f'joint "{j.name}" mimic multiplier', path,
                                         jline, 1.0),
                               _float_or(j.mimic.offset, f'joint "{j.name}" mimic offset', path,
                                         jline, 0.0))
        if j.type == "fixed":
            body_of[j.child], pose_of[j.child] = b, X
            info[j.name] = UrdfJoint(**common, body=b, joint=None, coordinates=())
            visit(j.child)
            continue
        cb = body_names(j.child)
        jn = joint_names(j.name)
        body_of[j.child], pose_of[j.child] = cb, np.eye(4)
        mass[cb] = _Mass()
        order.append(cb)
        pos = tuple(float(x) for x in X[:3, 3])
        R = X[:3, :3]
        ori = None if np.array_equal(R, np.eye(3)) else [[float(x) for x in r] for r in R]
        axis_name = _AXIS_NAMES.get(common["axis"])  # "x", "-y", ... or None
        ax = axis_name or common["axis"]
        if j.mimic is not None and mimic == "coupled":
            if j.type not in ("revolute", "continuous", "prismatic"):
                raise UrdfError(f'joint "{j.name}": a {j.type} joint cannot mimic another (only '
                                "revolute, continuous and prismatic joints can)", path, jline)
            # no coordinate of its own: the step follows the mimicked joint's (resolved below,
            # when every joint has its coordinate)
            body_spec[cb] = {"parent": b, "joint": None,
                             "mimic": (j.name, jn, common["mimic"], ax, pos, ori, j.type,
                                       jline)}
            info[j.name] = UrdfJoint(**common, body=cb, joint=jn, coordinates=())
            visit(j.child)
            continue
        try:
            if j.type in ("revolute", "continuous", "prismatic"):
                q = jn
                make = Prismatic if j.type == "prismatic" else Revolute
                joint = make(jn, se.Symbol(q), ax, position=pos, orientation=ori)
                qs: tuple[str, ...] = (q,)
            elif j.type == "floating":
                qs = tuple(f"{jn}_{s}" for s in ("x", "y", "z", "yaw", "pitch", "roll"))
                joint = Free(jn, _symbols(qs), "zyx", position=pos, orientation=ori)
            else:  # planar: the plane normal to the axis, which must be a frame axis
                normal = axis_name
                if normal is None or normal.startswith("-"):
                    raise UrdfError(
                        f'joint "{j.name}": a planar joint is read only with its axis '
                        "along +x, +y or +z of the joint frame (the plane's normal), got "
                        f"{' '.join(f'{a:g}' for a in axis)}", path, jline)
                a1, a2 = {"x": ("y", "z"), "y": ("z", "x"), "z": ("x", "y")}[normal]
                qs = (f"{jn}_{a1}", f"{jn}_{a2}", f"{jn}_rot")
                joint = Planar(jn, _symbols(qs), normal, position=pos, orientation=ori)
        except UrdfError:
            raise
        except ModelError as exc:
            raise UrdfError(f'joint "{j.name}": {exc}', path, jline) from None
        coords.extend(qs)
        coord_units.update({c: "m" if (j.type == "prismatic" or k < (
            3 if j.type == "floating" else 2 if j.type == "planar" else 0)) else "rad"
            for k, c in enumerate(qs)})
        body_spec[cb] = {"parent": b, "joint": joint}
        tau = None
        if actuated and len(qs) == 1:
            tau = f"tau_{qs[0]}"
            inputs.append(tau)
            forces.append(GeneralizedForce(f"actuator_{qs[0]}", se.Symbol(qs[0]),
                                           se.Symbol(tau)))
        if joint_damping and len(qs) == 1 and common.get("damping"):
            damping[f"d_{qs[0]}"] = float(common["damping"])
            forces.append(RotationalSpringDamper(f"damping_{qs[0]}", se.Symbol(qs[0]),
                                                 damping=se.Symbol(f"d_{qs[0]}")))
        info[j.name] = UrdfJoint(**common, body=cb, joint=jn, coordinates=qs, input=tau)
        visit(j.child)

    _couple_mimics(body_spec, info, path)
    if not coords:
        raise UrdfError("the robot has no moving joint (every joint is fixed and the base is "
                        "fixed): nothing moves; load it with floating_base=True for a free "
                        "rigid body", path)

    # --- bodies with their merged mass data as parameters ---
    params: dict[str, float] = {"g": g}
    units: dict[str, str] = {"g": "m/s^2"}
    bodies: list[Body] = []
    below = _mass_below(order, body_spec, mass)
    link_of = {v: k for k, v in body_names.names.items()}  # body -> URDF link
    for b in order:
        md = mass[b]
        spec = body_spec[b]
        urdf_link = link_of.get(b, b)
        jname = spec["joint"].name
        if below[b] <= 0.0:
            raise UrdfError(
                f'link "{urdf_link}" (joint "{jname}") and every link it carries have no mass '
                "(no <inertial>, or mass 0): the coordinates of that joint move nothing and "
                "the mass matrix is singular; give one of these links an <inertial>", path,
                src.line("link", urdf_link))
        if md.m == 0.0 and md.rotational:
            raise UrdfError(f'link "{urdf_link}": mass 0 with a nonzero inertia tensor, which no '
                            "rigid body has; give its mass or set the inertia to 0", path,
                            src.line("link", urdf_link))
        c, I = md.com_inertia()

        def param(pname: str, value: float, unit: str) -> se.Basic:
            # a number that is exactly 0 stays a literal 0: a massless body, a point mass and
            # the zero products of inertia are then zero for the stages, not only in value
            if value == 0.0:
                return se.Integer(0)
            params[pname], units[pname] = float(value), unit
            return se.Symbol(pname)

        m_sym = param(f"m_{b}", md.m, "kg")
        com = tuple(param(f"c{a}_{b}", float(c[k]), "m") for k, a in enumerate("xyz"))
        Isym: list[list[se.Basic]] = [[se.Integer(0)] * 3 for _ in range(3)]
        for r in range(3):
            for s in range(r, 3):
                Isym[r][s] = Isym[s][r] = param(f"I{'xyz'[r]}{'xyz'[s]}_{b}", float(I[r, s]),
                                                "kg*m^2")
        try:
            bodies.append(Body(b, spec["parent"], spec["joint"], mass=m_sym, com=com,
                               inertia=Isym))
        except ModelError as exc:
            raise UrdfError(f'link "{urdf_link}": {exc}', path,
                            src.line("link", urdf_link)) from None
    params.update(damping)

    units.update(coord_units)
    units.update({tau: "N*m" if coord_units[tau[4:]] == "rad" else "N" for tau in inputs})
    clash = sorted(set(coords) & set(params) | set(coords) & set(inputs))
    if clash:
        raise UrdfError(f"the coordinate name(s) {clash} (from joint names) collide with "
                        "jourdain's parameter or input names; rename the joints", path)
    try:
        system = System(coords, bodies, [Gravity((0, 0, -se.Symbol("g"))), *forces],
                        parameters=params, inputs=inputs, units=units, name=robot.name)
    except ModelError as exc:
        raise UrdfError(str(exc), path) from None

    # --- data for viewers and users ---
    link_data = tuple(UrdfLink(ln, body_of.get(ln, "world"), _pose(pose_of.get(ln, np.eye(4))))
                      for ln in link_names)
    visuals, collisions = [], []
    for lk in robot.links:
        for v in lk.visuals:
            visuals.append(_geometry(v, lk.name, body_of[lk.name], pose_of[lk.name], src,
                                     collision=False))
        for v in lk.collisions:
            collisions.append(_geometry(v, lk.name, body_of[lk.name], pose_of[lk.name], src,
                                        collision=True))
    zero = NominalMotion(
        "zero", tuple(se.Integer(0) for _ in coords), tuple(se.Integer(0) for _ in coords),
        tuple(se.Integer(0) for _ in coords),
        description="every joint coordinate 0 (under gravity an equilibrium only where the "
                    "inputs hold it)")
    descriptions = _descriptions(system, info.values(), link_data, floating_base)
    return UrdfModel(
        path=path, system=system, descriptions=descriptions,
        description=f'URDF robot "{robot.name}" ({Path(path).name})'
                    + (", floating base" if floating_base else ""),
        nominal=(zero,) if not floating_base else (),
        simulation=SimulationSettings(y0=(0.0,) * system.f, yd0=(0.0,) * system.f),
        robot=str(robot.name), floating_base=floating_base,
        joints=tuple(info[j.name] for j in robot.joints), links=link_data,
        visual_geometry=tuple(visuals), collision_geometry=tuple(collisions))


def _descriptions(system: System, joints: Any, links: Sequence[UrdfLink],
                  floating_base: bool) -> tuple[tuple[str, str], ...]:
    """One line per coordinate, input and mass parameter, for reports and ``check``."""
    out: dict[str, str] = {}
    if floating_base:
        for c in ROOT_COORDINATES:
            out[c] = f"floating base ({ROOT_JOINT}): {c[5:]}"
    for j in joints:
        lim = (f", limits [{j.lower:g}, {j.upper:g}]"
               if j.lower is not None and j.upper is not None and j.type != "continuous" else "")
        for c in j.coordinates:
            out[c] = f'{j.type} joint "{j.name}" ({j.parent} → {j.child}){lim}'
        if j.input:
            effort = f", effort limit {j.effort:g}" if j.effort is not None else ""
            out[j.input] = f'actuator of joint "{j.name}"{effort}'
    welded: dict[str, list[str]] = {}
    for lk in links:
        if lk.body != "world" and lk.name != lk.body:
            welded.setdefault(lk.body, []).append(lk.name)
    params = system.parameter_values
    for b in system.body_names:
        extra = welded.get(b, [])
        more = f" with the welded link(s) {', '.join(extra)}" if extra else ""
        for key, what in (("m", "mass"), ("cx", "centre of mass x"), ("cy", "centre of mass y"),
                          ("cz", "centre of mass z")):
            if f"{key}_{b}" in params:
                out[f"{key}_{b}"] = f"{what} of link {b}{more}"
        for a in ("xx", "xy", "xz", "yy", "yz", "zz"):
            if f"I{a}_{b}" in params:
                out[f"I{a}_{b}"] = f"inertia I{a} of link {b}{more} about its centre of mass"
    out["g"] = "gravity along -z"
    return tuple(out.items())


def _symbols(names: Sequence[str]) -> tuple[se.Symbol, ...]:
    return tuple(se.Symbol(n) for n in names)


def _axis(j: Any, path: str, line: int | None) -> np.ndarray:
    """The unit axis of a joint (URDF's default 1 0 0); the zero vector is refused."""
    a = np.asarray(j.axis if j.axis is not None else (1.0, 0.0, 0.0), dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise UrdfError(f'joint "{j.name}": <axis xyz> must be 3 finite numbers', path, line)
    n = float(np.linalg.norm(a))
    if j.type in ("revolute", "continuous", "prismatic", "planar") and n == 0.0:
        raise UrdfError(f'joint "{j.name}": the axis is the zero vector', path, line)
    return a / n if n > 0 else a


def _limits(j: Any, path: str, line: int | None) -> dict[str, float | None]:
    out: dict[str, float | None] = {}
    lim, dyn = j.limit, j.dynamics
    for key in ("lower", "upper", "effort", "velocity"):
        out[key] = _float(getattr(lim, key, None) if lim is not None else None,
                          f'joint "{j.name}" <limit {key}>', path, line)
    for key in ("damping", "friction"):
        out[key] = _float(getattr(dyn, key, None) if dyn is not None else None,
                          f'joint "{j.name}" <dynamics {key}>', path, line)
    return out


def _couple_mimics(body_spec: dict[str, dict], info: dict[str, UrdfJoint], path: str) -> None:
    """The joints of ``<mimic joint="d" multiplier="k" offset="o">``: one step about (along)
    their axis by ``k·q_d + o``, with ``q_d`` the coordinate of joint d, which both share (a
    General joint that drives no coordinate of its own)."""
    for spec in body_spec.values():
        if spec.get("joint") is not None or "mimic" not in spec:
            continue
        name, jn, (leader, k, o), ax, pos, ori, kind, line = spec["mimic"]
        target = info.get(leader)
        if target is None or len(target.coordinates) != 1:
            why = ("is not declared" if target is None else
                   "is itself a mimic joint" if target.mimic is not None and not target.coordinates
                   else "has no single coordinate (fixed, floating or planar)")
            raise UrdfError(f'joint "{name}": it mimics joint "{leader}", which {why}; a mimic '
                            "joint follows one revolute, continuous or prismatic joint", path,
                            line)
        value = k * se.Symbol(target.coordinates[0]) + o
        step = Trans(ax, value) if kind == "prismatic" else Rot(ax, value)
        try:
            spec["joint"] = General(jn, [step], position=pos, orientation=ori)
        except ModelError as exc:
            raise UrdfError(f'joint "{name}": {exc}', path, line) from None
