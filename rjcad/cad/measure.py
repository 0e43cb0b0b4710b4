"""What a joint's files and manifest need from its solids, as plain numbers (so that another process can build
them: ``rjcad.cad.process``), in the order the writer needs them: the shape (each body's triangles, the tendon
at rest, the axis), then the measurements (tendon moment arm and wrap, each body's volume, mass and centre,
the spring strips' volume), then the STEP file. Imports OCP, not trimesh."""

from __future__ import annotations

import time

import numpy as np

from rjcad.cad import export as ex
from rjcad.cad.joint import JointSolids, build_joint, ground_channel_points, moving_channel_points, strip_volume
from rjcad.cad.results import JointMeasures, JointShape
from rjcad.design.params import JointParams
from rjcad.io.manifest import BodyEntry


def body_entries(solids: dict, density_g_cm3: float) -> list[BodyEntry]:
    """Name, volume [mm³], mass [g] (at ``density_g_cm3``) and centre of mass [mm] of each solid: one volume
    integration per solid (volume and centre together)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    entries = []
    for n, s in solids.items():
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(s, props)
        c = props.CentreOfMass()
        v = float(props.Mass())
        entries.append(BodyEntry(n, v, v * density_g_cm3 / 1000.0, [float(c.X()), float(c.Y()), float(c.Z())]))
    return entries


def tendon_polyline(p: JointParams) -> np.ndarray:
    """Tendon centreline at rest for the preview: ground channel, over the eye, moving channel [mm]."""
    pts = ground_channel_points(p, p.link_length)[:-1] + moving_channel_points(p, p.link_length)
    return np.array(pts)


class LocalJoint:
    """The joint of ``p`` built in this process: ``shape()`` and ``measures()`` (each computed once), then
    ``step(name)`` (``rjcad.cad.process`` serves the same three from another process). ``solids`` holds the
    bodies once ``shape()`` has built them."""

    def __init__(self, p: JointParams):
        self.params = p
        self.solids: JointSolids | None = None
        self._shape: JointShape | None = None
        self._measures: JointMeasures | None = None

    def _built(self) -> JointSolids:
        """The bodies, which ``shape()`` builds (once)."""
        self.shape()
        assert self.solids is not None  # shape() set them
        return self.solids

    def shape(self) -> JointShape:
        if self._shape is None:
            p = self.params
            t0 = time.perf_counter()
            self.solids = s = build_joint(p)
            t1 = time.perf_counter()
            tri = {"ground": ex.triangulate(s.ground), "moving": ex.triangulate(s.moving)}
            t2 = time.perf_counter()
            self._shape = JointShape(
                tri,
                tendon_polyline(p),
                list(s.axis_point),
                list(s.axis_dir),
                {"build_s": t1 - t0, "triangulate_s": t2 - t1},
            )
        return self._shape

    def measures(self) -> JointMeasures:
        if self._measures is None:
            p, s = self.params, self._built()
            t0 = time.perf_counter()
            arm = ex.measure_moment_arm(s.moving, p.z_mid, p.tendon_line_diameter)
            wrap = ex.measure_wrap_angle(s.ground, p.tendon_diameter / 2)
            t1 = time.perf_counter()
            bodies = body_entries({"ground": s.ground, "moving": s.moving}, p.material_spec.density_g_cm3)
            self._measures = JointMeasures(arm, wrap, bodies, strip_volume(p), {"arm_wrap_s": t1 - t0})
        return self._measures

    def step(self, name: str = "joint") -> bytes:
        """The STEP file of both bodies, its assembly named ``name``."""
        s = self._built()
        return ex.step_bytes({"ground": s.ground, "moving": s.moving}, name)
