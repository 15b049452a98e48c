"""Robots from URDF files: ``Model.from_urdf(path, flexible={...})``.

A URDF (the Unified Robot Description Format's XML) describes a tree of links joined by joints. Each joint
places its child link's frame on the parent link's: T_child = T_parent · T_origin · T̃(q), T_origin =
Trans(xyz) · R3(yaw) R2(pitch) R1(roll) (the file's fixed-axis roll-pitch-yaw, the package's Euler ZYX
angles), T̃(q) a rotation by q about, or a translation by q along, the joint's unit ``axis`` (joint frame).
A link's ``<inertial>`` gives its mass, its centre of mass and the axes of its inertia tensor (the
``<origin>`` of the inertial frame, in the link frame) and the tensor about the centre of mass in those axes.

How the tree becomes bodies and joints:

- ``revolute`` and ``continuous`` joints become ``Joint.revolute``, ``prismatic`` ``Joint.prismatic``,
  ``floating`` ``Joint.free`` (ZYX angles, not quaternions), ``planar`` ``Joint.planar``. A joint's
  coordinate is the file's: the same q turns the same way. A body's frame is its link's frame when the joint's
  axis is +x, +y or +z; for another axis a, the body frame is the link frame turned by a constant rotation A
  that takes the coordinate axis it uses (z, or the axis nearest a) onto a, T_body = T_link · A, and the
  link's inertia is given in the body frame (``UrdfModel.frames`` keeps T_body_link = A⁻¹ for each link).
- ``fixed`` joints merge their child into the parent's body: masses added, the centre of mass and the inertia
  tensor combined by the parallel-axis theorem, as Pinocchio and MuJoCo do. The root link is fixed to the
  ground (``base="fixed"``: its mass and everything fixed to it goes to the ground) or joined to it by a
  free joint (``base="free"``).
- Joint limits, efforts and velocities are kept in ``UrdfModel.joints`` but not enforced (the coordinates
  are unbounded); ``<dynamics damping>`` becomes the joint's viscous damping (N·m·s/rad or N·s/m);
  ``friction`` is kept, not modelled; collision geometry, transmissions and Gazebo tags are ignored.
  ``UrdfModel.notes`` lists what was ignored.
- Each link's visual geometry is kept in ``UrdfModel.visuals`` (the viewer draws it): a primitive's size,
  a mesh's file name as written, its origin, scale and colour (``<material><color rgba>``, or a material of
  the robot named there), and for a mesh file that is found and read (STL, binary or ASCII, or Collada
  .dae: ``rigidfem.model.meshes``) its triangles. ``package://pkg/rest`` is looked for in the folders of
  ``package_dirs`` (``<folder>/pkg/rest``, or ``<folder>/rest`` for a folder named pkg; a dict maps a
  package to its folder), then in the URDF's folder and the folders above it alike, then as
  ``<URDF's folder>/rest``; ``file://`` names a path, and a plain name is relative to the URDF's folder.
  A mesh file not found, or not read (another format, or a broken file), is one note in
  ``UrdfModel.notes``, never an error: its body is drawn by its other visuals, or as its inertia's box.
  The visuals of a flexible link are not drawn (its beam's tube is) and their files are not read.
- A link named in ``flexible`` becomes a beam (``Model.add_beam``) from its joint frame to the origin of its
  child joint (``to``: the farthest one by default), divided into ``elements`` sdes. Its frame's x axis runs
  along the link, its z axis along the joint's axis (in-plane bending of the joint's own motion is
  ``bend_z``, out-of-plane ``bend_y``); the link's rfes are ``<link>.rfe0 ... <link>.rfe<m>``. The beam's
  mass and inertia come from its material and section (ρ A L, with the section's rotary inertia): the URDF's
  inertial of that link is dropped, or its mass kept by ``match_mass=True`` (the density set to
  m_urdf/(A L)). Child joints hang from the rfe that holds the point of the beam nearest their origin.

Refused, with the reason (a ValueError naming ``path``, ``base`` or ``flexible``): a file that is not XML or
whose root is not ``<robot>``, an xacro file not yet expanded, a joint naming a link that is not there, a link
that is the child of two joints (a closed chain: URDF describes trees; close loops with
``Model.add_loop_joint`` after loading), more than one root, ``mimic`` joints, a joint with a zero axis, a
massless link (or one whose inertia is not positive definite) on a moving joint, a flexible link that is not
in the file, has no child joint or is too short for its elements (each element at least as long as its
section's radius of gyration: a shorter piece is no beam).
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace
from pathlib import Path
from urllib.parse import unquote, urlparse

import numpy as np

from ..base import _checks
from . import meshes
from .frames import transform
from .joints import Joint
from .materials import Material, Section

#: The URDF joint types and what each becomes.
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
#: The keys of a flexible link's specification: ``Model.add_beam``'s, its end and the mass rule.
FLEXIBLE_KEYS = ("elements", "material", "section", "formulation", "deform", "linear", "tip_mass", "tip_inertia",
                 "tip_offset", "to", "match_mass")
_XACRO = "http://www.ros.org/wiki/xacro"
_AXES = np.eye(3)


# --- the file: links, joints, visuals ------------------------------------------------------------------------


@dataclass(frozen=True)
class Visual:
    """A link's visual geometry: ``kind`` "mesh", "box", "cylinder" (along the visual frame's z) or "sphere";
    ``filename`` (a mesh's, as written: ``package://...``), ``scale`` (3,) of a mesh, ``size`` (a box's sides,
    or (radius, length) of a cylinder, (radius,) of a sphere; m), ``origin`` (4, 4) the visual frame in the
    link frame, ``colour`` (r, g, b, a) in [0, 1] of its material or None. Once loaded (``UrdfModel.visuals``):
    ``path`` the mesh file found (None: not found) and ``mesh`` its ``meshes.Mesh`` (vertices in m in the
    visual frame before ``scale``; None: not read). A mesh's point v is at ``origin · diag(scale) · v`` in the
    link frame."""

    kind: str
    origin: np.ndarray
    filename: str | None = None
    scale: tuple = (1.0, 1.0, 1.0)
    size: tuple = ()
    colour: tuple | None = None
    path: str | None = None
    mesh: object = None


@dataclass(frozen=True)
class Link:
    """A URDF link: ``mass`` (kg), ``inertial`` (4, 4) the inertial frame in the link frame (its origin the
    centre of mass), ``inertia`` (3, 3) about the centre of mass in the inertial frame's axes (kg·m²)."""

    name: str
    mass: float
    inertial: np.ndarray
    inertia: np.ndarray
    visuals: tuple = ()


@dataclass(frozen=True)
class UrdfJoint:
    """A URDF joint: ``kind`` (``JOINT_TYPES``), ``origin`` (4, 4) the joint (= child link) frame in the parent
    link's, ``axis`` (3,) unit, in the joint frame; ``limits`` {"lower", "upper" (rad or m), "effort" (N·m or N),
    "velocity" (rad/s or m/s)} as given (not enforced); ``damping`` and ``friction`` of ``<dynamics>``."""

    name: str
    kind: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    limits: dict = field(default_factory=dict)
    damping: float = 0.0
    friction: float = 0.0


@dataclass(frozen=True)
class Robot:
    """A parsed URDF: its ``name``, ``links`` and ``joints`` by name, in the file's order, and the ``root`` link."""

    name: str
    links: dict
    joints: dict
    root: str

    def children(self, link: str) -> list:
        """The joints whose parent is ``link``, in the file's order."""
        return [j for j in self.joints.values() if j.parent == link]


def _floats(element, attribute: str, n: int, default, where: str) -> np.ndarray:
    text = element.get(attribute) if element is not None else None
    if text is None:
        return np.array(default, dtype=float)
    try:
        values = np.array([float(v) for v in text.split()])
    except ValueError:
        values = np.array([])
    if values.shape != (n,) or not np.all(np.isfinite(values)):
        raise _checks.refuse(f"path: expected {n} finite numbers in {attribute}=\"...\" of {where}, got {text!r}")
    return values


def _number(element, attribute: str, where: str, default: float = 0.0) -> float:
    return float(_floats(element, attribute, 1, (default,), where)[0])


def _origin(element, where: str) -> np.ndarray:
    """T = Trans(xyz) R3(yaw) R2(pitch) R1(roll) of an ``<origin xyz rpy>`` (identity when absent)."""
    o = element.find("origin") if element is not None else None
    xyz = _floats(o, "xyz", 3, (0.0, 0.0, 0.0), where)
    roll, pitch, yaw = _floats(o, "rpy", 3, (0.0, 0.0, 0.0), where)
    return transform(xyz, (yaw, pitch, roll))


def _link(element, materials: dict) -> Link:
    name = element.get("name")
    where = f"link {name!r}"
    inertial = element.find("inertial")
    mass, I = 0.0, np.zeros((3, 3))
    if inertial is not None:
        mass = _number(inertial.find("mass"), "value", where)
        i = inertial.find("inertia")
        ixx, ixy, ixz, iyy, iyz, izz = (_number(i, k, where) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
        I = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    if mass < 0.0:
        raise _checks.refuse(f"path: expected a mass >= 0 kg of {where}, got {mass}")
    visuals = tuple(_visual(v, where, materials) for v in element.findall("visual"))
    return Link(name, mass, _origin(inertial, where), I, visuals)


def _colour(material, where: str):
    """(r, g, b, a) of a ``<material>``'s ``<color rgba>``, or None."""
    colour = material.find("color") if material is not None else None
    if colour is None:
        return None
    return tuple(float(x) for x in np.clip(_floats(colour, "rgba", 4, (0.5, 0.5, 0.5, 1.0), where), 0.0, 1.0))


def _visual(element, where: str, materials: dict) -> Visual:
    origin = _origin(element, where)
    material = element.find("material")
    colour = _colour(material, where)
    if colour is None and material is not None:
        colour = materials.get(material.get("name"))
    geometry = element.find("geometry")
    shape = next(iter(geometry), None) if geometry is not None else None
    if shape is None:
        return Visual("none", origin, colour=colour)
    if shape.tag == "mesh":
        scale = tuple(float(x) for x in _floats(shape, "scale", 3, (1, 1, 1), where))
        return Visual("mesh", origin, shape.get("filename"), scale, colour=colour)
    sizes = {"box": lambda: tuple(_floats(shape, "size", 3, (0, 0, 0), where)),
             "cylinder": lambda: (_number(shape, "radius", where), _number(shape, "length", where)),
             "sphere": lambda: (_number(shape, "radius", where),)}
    return Visual(shape.tag, origin, size=sizes[shape.tag]() if shape.tag in sizes else (), colour=colour)


def _joint(element, links) -> UrdfJoint:
    name, kind = element.get("name"), element.get("type")
    where = f"joint {name!r}"
    if kind not in JOINT_TYPES:
        raise _checks.refuse(f"path: expected a joint type from {JOINT_TYPES} for {where}, got {kind!r}")
    if element.find("mimic") is not None:
        raise _checks.refuse(f"path: expected joints without <mimic> ({where} mimics "
                             f"{element.find('mimic').get('joint')!r}: a constraint between coordinates, not supported)")
    ends = []
    for tag in ("parent", "child"):
        e = element.find(tag)
        link = e.get("link") if e is not None else None
        if link not in links:
            raise _checks.refuse(f"path: expected the {tag} of {where} to be a link of the file, got {link!r}")
        ends.append(link)
    axis = _floats(element.find("axis"), "xyz", 3, (1.0, 0.0, 0.0), where)
    if kind not in ("fixed", "floating"):
        n = np.linalg.norm(axis)
        if not n > 0.0:
            raise _checks.refuse(f"path: expected a nonzero axis of {where}, got {axis.tolist()}")
        axis = axis / n
    limit, dynamics = element.find("limit"), element.find("dynamics")
    limits = {k: _number(limit, k, where) for k in ("lower", "upper", "effort", "velocity")
              if limit is not None and limit.get(k) is not None}
    damping, friction = _number(dynamics, "damping", where), _number(dynamics, "friction", where)
    if damping < 0.0:
        raise _checks.refuse(f"path: expected a damping >= 0 of {where}, got {damping}")
    return UrdfJoint(name, kind, *ends, _origin(element, where), axis, limits, damping, friction)


def parse(path) -> Robot:
    """The links and joints of the URDF file at ``path`` (str or os.PathLike); see the module's docstring.
    A missing file is a FileNotFoundError; a file that is not a URDF tree a ValueError naming ``path``."""
    path = _checks.path(path)
    try:
        root = ET.parse(os.fspath(path)).getroot()
    except ET.ParseError as error:
        raise _checks.refuse(f"path: expected a URDF file (XML), got {os.fspath(path)!r} ({error})") from None
    if root.tag != "robot":
        raise _checks.refuse(f"path: expected a URDF file whose root element is <robot>, got <{root.tag}>")
    if any(e.tag.startswith(f"{{{_XACRO}}}") for e in root.iter()) or "${" in ET.tostring(root, encoding="unicode"):
        raise _checks.refuse("path: expected a URDF file, got a xacro file (expand it with xacro first)")
    materials = {e.get("name"): _colour(e, f"material {e.get('name')!r}") for e in root.findall("material")}
    links = {}
    for e in root.findall("link"):
        if not e.get("name") or e.get("name") in links:
            raise _checks.refuse(f"path: expected links of unique non-empty names, got {e.get('name')!r} twice or empty")
        links[e.get("name")] = _link(e, materials)
    joints = {}
    for e in root.findall("joint"):
        if not e.get("name") or e.get("name") in joints:
            raise _checks.refuse(f"path: expected joints of unique non-empty names, got {e.get('name')!r} twice or empty")
        joints[e.get("name")] = _joint(e, links)
    return Robot(root.get("name", ""), links, joints, _root(links, joints))


def _root(links: dict, joints: dict) -> str:
    """The one link that is no joint's child; a link that is the child of two joints is a closed chain."""
    parent_joint = {}
    for j in joints.values():
        if j.child in parent_joint:
            raise _checks.refuse(f"path: expected a tree (each link the child of one joint), got link {j.child!r} the "
                                 f"child of joints {parent_joint[j.child]!r} and {j.name!r}: a closed chain (load the "
                                 f"tree and close the loop with Model.add_loop_joint)")
        parent_joint[j.child] = j.name
    roots = [name for name in links if name not in parent_joint]
    if len(roots) != 1:
        raise _checks.refuse(f"path: expected one root link (no joint's child), got {roots or 'none: a cycle'}")
    reached, stack = set(), [roots[0]]
    while stack:
        link = stack.pop()
        reached.add(link)
        stack += [j.child for j in joints.values() if j.parent == link]
    if len(reached) != len(links):
        cut = sorted(set(links) - reached)
        raise _checks.refuse(f"path: expected every link connected to the root {roots[0]!r}, got {cut} in a cycle")
    return roots[0]


# --- what the model keeps ------------------------------------------------------------------------------------


@dataclass
class UrdfModel:
    """What ``Model.from_urdf`` made of the file (``model.urdf``).

    Attributes
    ----------
    robot : Robot
        The parsed file (links, joints, limits, visuals).
    bodies : dict
        Link name -> the ``Body`` its link frame is fixed on (``model.ground`` for the base fixed to it; for a
        flexible link its first rfe).
    frames : dict
        Link name -> (4, 4) T_body_link, the link frame in that body's frame (at zero deformation for a
        flexible link): a point r of the link is at ``bodies[link].point(T[:3, :3] @ r + T[:3, 3])``.
    coordinates : dict
        Joint name -> the names of its coordinates in ``System.coordinate_names`` (a tuple; empty for fixed).
    joint_bodies : dict
        Moving joint name -> the ``Body`` it moves (its child link's body; a flexible link's first rfe): the
        handle ``Model.prescribe`` and ``add_generalized_force`` take.
    beams : dict
        Flexible link name -> its ``Beam`` handle.
    visuals : dict
        Link name -> its ``Visual`` tuple, origins in the link frame, meshes found and read (those of a
        flexible link as written: not drawn, not read).
    notes : tuple of str
        What the file holds that the model does not use (limits, friction, masses replaced by beams) and the
        visual geometry that cannot be drawn (mesh files not found or not read, a flexible link's).
    """

    robot: Robot
    bodies: dict
    frames: dict
    coordinates: dict
    joint_bodies: dict
    beams: dict
    visuals: dict
    notes: tuple

    def point(self, link: str, r=(0.0, 0.0, 0.0)):
        """The ``Point`` at ``r`` (m, link frame) of the link ``link`` (its origin by default)."""
        if link not in self.frames:
            raise _checks.refuse(f"link: expected a link of the file ({', '.join(self.frames)}), got {link!r}")
        T = self.frames[link]
        return self.bodies[link].point(T[:3, :3] @ _checks.vec3(r, "r") + T[:3, 3])


# --- the model -----------------------------------------------------------------------------------------------


def _axis_frame(axis: np.ndarray) -> tuple[np.ndarray, str]:
    """(A, letter): a rotation A (4, 4) and the coordinate axis e it uses, with A e = ``axis``; A = 1 when the
    axis is +x, +y or +z, else the least rotation from the nearest coordinate axis (a half turn for −x, −y, −z)."""
    k = int(np.argmax(np.abs(axis)))
    e = _AXES[k]
    A = np.eye(4)
    c = float(e @ axis)
    if c > 1.0 - 1e-15:
        return A, "xyz"[k]
    if c < -1.0 + 1e-15:  # a half turn about the next axis
        A[:3, :3] = 2.0 * np.outer(_AXES[(k + 1) % 3], _AXES[(k + 1) % 3]) - np.eye(3)
        return A, "xyz"[k]
    v = np.cross(e, axis)  # Rodrigues: R e = axis, about e × axis
    K = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    A[:3, :3] = np.eye(3) + K + K @ K / (1.0 + c)
    return A, "xyz"[k]


def _rigid_joint(j, damping: float):
    """(rigidfem joint, A) of a URDF joint other than fixed."""
    if j.kind == "floating":
        return Joint.free(), np.eye(4)
    A, letter = _axis_frame(j.axis)
    if j.kind in ("revolute", "continuous"):
        return Joint.revolute(letter, damping=damping), A
    if j.kind == "prismatic":
        return Joint.prismatic(letter, damping=damping), A
    plane = {"x": "yz", "y": "zx", "z": "xy"}[letter]  # planar: the plane normal to the axis
    return Joint.planar(plane, damping=damping), A


def _combined(parts) -> tuple[float, np.ndarray, np.ndarray]:
    """(m, c, I_c) of rigid parts (m_k, T_k: the inertial frame in the body frame, I_k about its c.o.m.):
    m = Σ m_k, c = Σ m_k c_k / m, I_c = Σ R_k I_k R_kᵀ + m_k (|d_k|² 1 − d_k d_kᵀ), d_k = c_k − c."""
    m = sum(mk for mk, _, _ in parts)
    if not m > 0.0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    c = sum(mk * T[:3, 3] for mk, T, _ in parts) / m
    I = np.zeros((3, 3))
    for mk, T, Ik in parts:
        R, d = T[:3, :3], T[:3, 3] - c
        I += R @ Ik @ R.T + mk * (d @ d * np.eye(3) - np.outer(d, d))
    return m, c, 0.5 * (I + I.T)


class _Builder:
    """Adds a parsed robot's links to a model, from the root down (depth first, the file's order)."""

    def __init__(self, model, robot: Robot, flexible: dict, base: str):
        self.model, self.robot, self.flexible, self.base = model, robot, flexible, base
        self.bodies, self.frames, self.coordinates, self.beams, self.notes = {}, {}, {}, {}, []
        self.joint_bodies = {}

    def build(self) -> UrdfModel:
        root = self.robot.root
        if root in self.flexible:
            self.add_beam(root, None, np.eye(4), self.model.ground)
        else:
            self.add_group(root, None, np.eye(4), self.model.ground)
        limited = [j.name for j in self.robot.joints.values() if j.limits and j.kind != "fixed"]
        if limited:
            self.notes.append(f"limits not enforced (the coordinates are unbounded): {', '.join(limited)}")
        rubbing = [j.name for j in self.robot.joints.values() if j.friction]
        if rubbing:
            self.notes.append(f"joint friction not modelled: {', '.join(rubbing)}")
        visuals = {name: link.visuals for name, link in self.robot.links.items()}
        return UrdfModel(self.robot, self.bodies, self.frames, self.coordinates, self.joint_bodies, self.beams, visuals,
                         tuple(self.notes))

    def fixed_group(self, link: str) -> list:
        """[(link, T_link_member)] of ``link`` and the links fixed to it (not through a flexible link)."""
        group, stack = [], [(link, np.eye(4))]
        while stack:
            name, T = stack.pop(0)
            group.append((name, T))
            stack += [(j.child, T @ j.origin) for j in self.robot.children(name)
                      if j.kind == "fixed" and j.child not in self.flexible]
        return group

    def add_group(self, link: str, joint, B: np.ndarray, parent) -> None:
        """The rigid link ``link`` (and what is fixed to it) hanging by the URDF ``joint`` (None: the root) from
        ``parent`` (a Body) at the joint frame B (4, 4, in the parent's frame)."""
        group = self.fixed_group(link)
        moving = joint is not None and joint.kind != "fixed" or joint is None and self.base == "free"
        if joint is None or joint.kind == "fixed":
            spec, A = (Joint.free(), np.eye(4)) if moving else (Joint.fixed(), np.eye(4))
        else:
            spec, A = _rigid_joint(joint, joint.damping)
        A_inv = np.linalg.inv(A)
        parts = [(self.robot.links[n].mass, A_inv @ T @ self.robot.links[n].inertial, self.robot.links[n].inertia)
                 for n, T in group if self.robot.links[n].mass > 0.0]
        mass, com, inertia = _combined(parts)
        on_ground = parent.index < 0 and not moving
        if on_ground or (not moving and mass == 0.0):  # fixed to its parent with nothing to weigh: a frame only
            body, T_body_joint = parent, B
        else:
            if not mass > 0.0 or np.linalg.eigvalsh(inertia)[0] <= 0.0:
                what = "no mass" if not mass > 0.0 else f"an inertia of principal moments {np.linalg.eigvalsh(inertia)}"
                argument = "base" if joint is None else "path"
                raise _checks.refuse(f"{argument}: expected a mass > 0 and a positive definite inertia of link {link!r} "
                                     f"(with the links fixed to it), a body of its own (on a moving joint or fixed on "
                                     f"a beam), got {what}")
            body = self.model.add_body(link, parent, spec, mass=mass, inertia=inertia, com=com, placement=B @ A)
            T_body_joint = A_inv
        if joint is not None and body is not parent:
            self.coordinates[joint.name] = tuple(f"{body.name}.{c}" for c in spec.coordinates)
            if spec.coordinates:
                self.joint_bodies[joint.name] = body
        elif joint is not None:
            self.coordinates[joint.name] = ()
        for name, T in group:
            self.bodies[name], self.frames[name] = body, T_body_joint @ T
            for j in self.robot.children(name):
                if j.kind == "fixed" and j.child not in self.flexible:
                    self.coordinates[j.name] = ()
                else:
                    self.add_child(j, body, self.frames[name] @ j.origin)

    def add_child(self, joint, parent, B: np.ndarray) -> None:
        if joint.child in self.flexible:
            self.add_beam(joint.child, joint, B, parent)
        else:
            self.add_group(joint.child, joint, B, parent)

    def add_beam(self, link: str, joint, B: np.ndarray, parent) -> None:
        """The flexible link ``link``: a beam from its joint frame (B in ``parent``'s frame) to its end joint."""
        spec = self.flexible[link]
        where = f"flexible[{link!r}]"
        children = self.robot.children(link)
        end = _end_joint(children, spec.get("to"), where)
        L = float(np.linalg.norm(end.origin[:3, 3]))
        if not L > 1e-9:
            raise _checks.refuse(f"{where}: expected a link whose end joint {end.name!r} lies away from its joint "
                                 f"frame (the beam runs between them), got a length of {L:g} m")
        d = end.origin[:3, 3] / L
        kind = "fixed" if joint is None else joint.kind
        if kind in ("revolute", "continuous", "prismatic"):
            rf_joint, A = _beam_joint(kind, joint.axis, d, joint.damping, where)
        elif kind in ("fixed", "floating"):
            rf_joint, A = (Joint.free() if kind == "floating" or self.base == "free" else Joint.fixed()), _frame_on(d)
        else:
            raise _checks.refuse(f"{where}: expected a link on a revolute, continuous, prismatic, fixed or floating "
                                 f"joint, got a {kind} joint")
        material = _beam_material(spec, self.robot.links[link].mass, L, where)
        _check_elements(spec["elements"], spec["section"], L, where)
        options = {k: spec[k] for k in ("formulation", "deform", "linear", "tip_mass", "tip_inertia", "tip_offset")
                   if k in spec}
        beam = self.model.add_beam(link, parent, L, material, spec["section"], spec["elements"], joint=rf_joint,
                                   placement=B @ A, **options)
        urdf_mass = self.robot.links[link].mass
        self.notes.append(f"{link}: a beam of {sum(r.mass for r in beam.rfe):.6g} kg over {L:.6g} m "
                          f"replaces the file's inertial ({urdf_mass:.6g} kg)")
        self.beams[link] = beam
        if joint is not None:
            self.coordinates[joint.name] = tuple(f"{beam.rfes[0].name}.{c}" for c in rf_joint.coordinates)
            if rf_joint.coordinates:
                self.joint_bodies[joint.name] = beam.rfes[0]
        A_inv = np.linalg.inv(A)
        self.bodies[link], self.frames[link] = beam.rfes[0], A_inv
        for j in children:
            s = float(d @ j.origin[:3, 3])
            k = min(max(int(np.floor(s / (L / beam.elements) + 0.5)), 0), beam.elements)
            at = transform((-beam.frames[k], 0.0, 0.0)) @ A_inv @ j.origin  # the joint frame in rfe k's frame
            self.add_child(j, beam.rfes[k], at)


def _end_joint(children: list, to, where: str):
    """The joint at the beam's end: the one named ``to``, else the child joint farthest from the link's origin."""
    if not children:
        raise _checks.refuse(f"{where}: expected a link with a child joint (the beam ends at its origin), got a leaf")
    if to is None:
        return max(children, key=lambda j: np.linalg.norm(j.origin[:3, 3]))
    named = [j for j in children if j.name == to]
    if not named:
        raise _checks.refuse(f"{where}: expected 'to' to name a child joint of the link "
                             f"({', '.join(j.name for j in children)}), got {to!r}")
    return named[0]


def _frame_on(d: np.ndarray, z=None) -> np.ndarray:
    """A (4, 4) rotation whose x axis is ``d`` and whose z axis is the unit ``z`` (d made ⟂ z, for an axis ⟂ d to
    rounding), or without ``z`` the link's z (or y) made ⟂ d."""
    if z is None:
        z = _AXES[2] if abs(d[2]) < 0.9 else _AXES[1]
        z = z - (z @ d) * d
        z /= np.linalg.norm(z)
    else:
        d = d - (d @ z) * z
        d /= np.linalg.norm(d)
    A = np.eye(4)
    A[:3, :3] = np.column_stack([d, np.cross(z, d), z])
    return A


def _beam_joint(kind: str, axis: np.ndarray, d: np.ndarray, damping: float, where: str):
    """(joint, A) of a flexible link's joint: the beam frame's x along the link (d), its z along the axis — or its x
    when the axis runs along the link."""
    make = Joint.prismatic if kind == "prismatic" else Joint.revolute
    c = float(axis @ d)
    if c > 1.0 - 1e-9:
        return make("x", damping=damping), _frame_on(axis)
    if abs(c) < 1e-9:
        return make("z", damping=damping), _frame_on(d, axis)
    raise _checks.refuse(f"{where}: expected a link whose joint axis is perpendicular to it or along it (towards its "
                         f"end), got an axis at {math.degrees(math.acos(max(-1.0, min(1.0, c)))):.3g} degrees to it")


def _beam_material(spec: dict, urdf_mass: float, L: float, where: str):
    """The beam's material: as given, or (``match_mass``) with the density that gives it the file's mass."""
    material, section = spec["material"], spec["section"]
    if not spec.get("match_mass", False):
        return material
    if not isinstance(material, Material) or not isinstance(section, Section):
        raise _checks.refuse(f"{where}: expected one Material and one Section with match_mass (a uniform beam), got "
                             f"{_checks._short(material)} and {_checks._short(section)}")
    if not urdf_mass > 0.0:
        raise _checks.refuse(f"{where}: expected a link with a mass in the file for match_mass, got {urdf_mass} kg")
    return replace(material, rho=urdf_mass / (section.A * L))


def _check_elements(elements, section, L: float, where: str) -> None:
    """Each element Δ = L/m at least as long as the section's radius of gyration sqrt(max(Iy, Iz)/A): a shorter
    piece is no beam (its bending is not Euler–Bernoulli's, on which the sde constants EI/Δ rest)."""
    if isinstance(elements, bool) or not isinstance(elements, (int, np.integer)) or elements < 1:
        raise _checks.refuse(f"{where}: expected 'elements' a positive integer number of sdes, got {elements!r}")
    d = L / int(elements)
    if isinstance(section, Section):
        sections = [section]
    elif callable(section):
        sections = [section((k + 0.5) * d) for k in range(int(elements))]
    else:
        sections = list(section) if isinstance(section, (list, tuple)) else []
    radii = [math.sqrt(max(s.Iy, s.Iz) / s.A) for s in sections if isinstance(s, Section)]
    if radii and d < max(radii):
        most = int(L / max(radii))
        raise _checks.refuse(f"{where}: expected 'elements' at most {most} on a link of {L:.4g} m (each element at least "
                             f"as long as its section's radius of gyration, {max(radii):.3g} m), got {elements}: the "
                             f"link is too short for {elements} elements")


def _flexible(flexible, robot: Robot) -> dict:
    """``flexible`` checked: link name -> its specification (a dict of FLEXIBLE_KEYS)."""
    if flexible is None:
        return {}
    if not isinstance(flexible, dict):
        raise _checks.refuse(f"flexible: expected a dict of link names to beam specifications, got "
                             f"{_checks._short(flexible)}")
    out = {}
    for link, spec in flexible.items():
        if link not in robot.links:
            raise _checks.refuse(f"flexible: expected names of links of the file ({', '.join(robot.links)}), got "
                                 f"{link!r}")
        if not isinstance(spec, dict):
            raise _checks.refuse(f"flexible[{link!r}]: expected a dict of add_beam's arguments (elements, material, "
                                 f"section, ...), got {_checks._short(spec)}")
        unknown = [k for k in spec if k not in FLEXIBLE_KEYS]
        missing = [k for k in ("elements", "material", "section") if k not in spec]
        if unknown or missing:
            raise _checks.refuse(f"flexible[{link!r}]: expected the keys elements, material, section and optionally "
                                 f"{', '.join(FLEXIBLE_KEYS[3:])}, got {'unknown ' + str(unknown) if unknown else ''}"
                                 f"{' and ' if unknown and missing else ''}{'no ' + str(missing) if missing else ''}")
        out[link] = dict(spec)
    return out


def _package_dirs(package_dirs):
    """``package_dirs`` checked: [(package or None, folder)] of a folder, a sequence of folders or a dict of
    package names to folders (each a str or os.PathLike that exists)."""
    if package_dirs is None:
        return []
    if isinstance(package_dirs, dict):
        items = list(package_dirs.items())
    elif isinstance(package_dirs, (list, tuple)):
        items = [(None, d) for d in package_dirs]
    else:
        items = [(None, package_dirs)]
    out = []
    for key, folder in items:
        if not (isinstance(folder, os.PathLike) or isinstance(folder, str) and folder) or \
                not (key is None or isinstance(key, str) and key) or not os.path.isdir(folder):
            raise _checks.refuse(f"package_dirs: expected a folder (str or os.PathLike) that exists, a sequence of "
                                 f"them or a dict of package names to them, got {_checks._short(folder)}"
                                 f"{'' if key is None else f' for {key!r}'}")
        out.append((key, Path(folder)))
    return out


def _resolve(filename: str, folder: Path, package_dirs: list):
    """The mesh file ``filename`` names (see the module's docstring), or None when no candidate is a file."""
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://"):].partition("/")
        candidates = []
        for key, d in package_dirs:
            if key is None:
                candidates += [d / package / rest] + ([d / rest] if d.name == package else [])
            elif key == package:
                candidates.append(d / rest)
        for d in (folder, *folder.parents):
            candidates += [d / package / rest] + ([d / rest] if d.name == package else [])
        candidates.append(folder / rest)
    elif filename.startswith("file://"):
        candidates = [Path(unquote(urlparse(filename).path))]
    else:
        candidates = [folder / filename]
    return next((c for c in candidates if c.is_file()), None)


def _load_visuals(robot: Robot, folder: Path, package_dirs: list, flexible) -> tuple[dict, list]:
    """(link name -> its visuals with their mesh files found and read, notes): each file read once; the
    visuals of the links in ``flexible`` as written."""
    visuals, missing, unread, skipped, read = {}, [], [], [], {}
    for name, link in robot.links.items():
        if name in flexible:
            visuals[name] = link.visuals
            if link.visuals:
                skipped.append(name)
            continue
        loaded = []
        for v in link.visuals:
            if v.kind == "mesh" and v.filename:
                found = _resolve(v.filename, folder, package_dirs)
                if found is None:
                    missing.append(v.filename)
                else:
                    if found not in read:
                        try:
                            read[found] = meshes.read(found)
                        except (meshes.UnreadableMesh, ValueError, OSError) as error:
                            read[found] = None
                            unread.append(f"{v.filename} ({error})")
                    colour = v.colour or (read[found].colour if read[found] is not None else None)
                    v = replace(v, path=str(found), mesh=read[found], colour=colour)
            loaded.append(v)
        visuals[name] = tuple(loaded)
    notes = []
    if missing:
        notes.append(f"mesh files not found (not drawn; a body with no other visual shows its inertia's box): "
                     f"{', '.join(dict.fromkeys(missing))}")
    if unread:
        notes.append(f"mesh files not read (not drawn): {'; '.join(dict.fromkeys(unread))}")
    if skipped:
        notes.append(f"visuals of flexible links not drawn (their beams' tubes are): {', '.join(skipped)}")
    return visuals, notes


def from_urdf(model, path, flexible=None, base: str = "fixed", package_dirs=None) -> UrdfModel:
    """Add the robot of the URDF file ``path`` to the empty ``model`` (see ``Model.from_urdf``)."""
    robot = parse(path)
    if base not in ("fixed", "free"):
        raise _checks.refuse(f"base: expected 'fixed' (the root link fixed to the ground) or 'free' (a free joint), "
                             f"got {base!r}")
    folders = _package_dirs(package_dirs)
    flexible = _flexible(flexible, robot)
    built = _Builder(model, robot, flexible, base).build()
    visuals, notes = _load_visuals(robot, Path(os.fspath(path)).resolve().parent, folders, flexible)
    built.visuals, built.notes = visuals, built.notes + tuple(notes)
    return built
