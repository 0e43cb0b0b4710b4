"""The Python API: design a spring, build a joint or a finger, write, check and simulate it, with the CLI's
keywords (the TOML keys of ``--config``; ``stiffness`` in N·mm/rad) and units (mm, N; degrees only where a name
ends in ``_deg``). Errors are the CLI's (``rjcad.errors``), raised.

``import rjcad`` does not import this module: ``rjcad.build_joint`` and the other names load it on first use, and
OpenCASCADE (OCP), trimesh and the rest load only when a build, a check or a simulation runs. ``rjcad joint`` and
``rjcad finger`` read their input through ``joint_params`` and ``finger_params`` and write through the functions
``Joint.write`` and ``Finger.write`` use (``rjcad.cad.build.write_joint_files``, ``write_finger_files``).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rjcad.errors import MissingExtra, ParameterError
from rjcad.fields import JOINT_FIELDS, SPRING_FIELDS, from_keywords, merge_config, spring_kwargs
from rjcad.paper import FINGER
from rjcad.physics.grasp_result import Grasp
from rjcad.physics.objects import Box as _Box
from rjcad.physics.objects import Cylinder, Object

if TYPE_CHECKING:
    import trimesh

    from rjcad.cad.build import FingerBuild, JointBuild
    from rjcad.check.report import Report
    from rjcad.design.finger_params import FingerParams
    from rjcad.design.params import JointParams
    from rjcad.io.manifest import Manifest
    from rjcad.spring import SpringDesign

__all__ = [
    "Box",
    "Closure",
    "Cylinder",
    "Finger",
    "Grasp",
    "Joint",
    "Spring",
    "build_finger",
    "build_joint",
    "design_spring",
    "finger_params",
    "grasp",
    "joint_params",
]

#: A path to a file or directory, as ``open`` takes it.
PathLike = str | os.PathLike[str]

#: ``Finger.simulate``'s ranges, those of ``rjcad simulate finger``: stroke (0, 1000] mm, steps [10, 100000] each
#: way, tendon friction coefficient [0, 2].
MAX_STROKE_MM = 1000.0
STEPS = (10, 100000)
MAX_MU_T = 2.0


def _json(data: Any) -> dict[str, Any]:
    """``data`` as the JSON object a file holds (a fresh copy: plain dicts, lists, floats)."""
    out: dict[str, Any] = json.loads(json.dumps(data))
    return out


# --------------------------------------------------------------------------- spring


class Spring:
    """A spring design, as ``rjcad spring`` prints it: ``design`` (``rjcad.spring.SpringDesign``, mm and rad) and
    ``manifest``, the JSON object of ``rjcad spring --json``."""

    def __init__(self, design: SpringDesign) -> None:
        self.design = design

    @property
    def manifest(self) -> dict[str, Any]:
        """The JSON object of ``rjcad spring --json`` (a fresh copy)."""
        return _json(self.design.to_dict())

    def plot(self, path: PathLike) -> Path:
        """Write ``rjcad spring --plot``'s PNG (torque against wind-up; the strip printed and wound) to ``path``."""
        from rjcad.spring.plot import write_plot

        write_plot(self.design, str(path))
        return Path(path)

    def __repr__(self) -> str:
        d = self.design
        return f"Spring(b={d.width:.3g} mm, t={d.thickness:.3g} mm, L={d.length:.4g} mm)"


def design_spring(
    *,
    stiffness: float | None = None,
    rotation_deg: float | None = None,
    preload_deg: float | None = None,
    material: str | None = None,
    printer: str | None = None,
    safety_factor: float | None = None,
    end: str | None = None,
    springs: int | None = None,
    arms: int | None = None,
    min_gap_mm: float | None = None,
    width_min_mm: float | None = None,
    width_max_mm: float | None = None,
    inner_radius_min_mm: float | None = None,
    inner_radius_max_mm: float | None = None,
    max_outer_radius_mm: float | None = None,
    min_turns: float | None = None,
    min_cycles: float | None = None,
    backlash_mm: float | None = None,
    config: PathLike | None = None,
) -> Spring:
    """Design a joint's springs as ``rjcad spring`` does: its options as keywords (None: its default; rotation 90°),
    ``config`` a TOML file of the same keys (keywords win). ``stiffness`` [N·mm/rad] is required, here or in
    ``config``."""
    from rjcad.spring import SpringRequirement
    from rjcad.spring.optimise import design_spring as optimise

    given = from_keywords(
        dict(
            stiffness=stiffness,
            rotation_deg=rotation_deg,
            preload_deg=preload_deg,
            material=material,
            printer=printer,
            safety_factor=safety_factor,
            end=end,
            springs=springs,
            arms=arms,
            min_gap_mm=min_gap_mm,
            width_min_mm=width_min_mm,
            width_max_mm=width_max_mm,
            inner_radius_min_mm=inner_radius_min_mm,
            inner_radius_max_mm=inner_radius_max_mm,
            max_outer_radius_mm=max_outer_radius_mm,
            min_turns=min_turns,
            min_cycles=min_cycles,
            backlash_mm=backlash_mm,
        ),
        SPRING_FIELDS,
    )
    kwargs = spring_kwargs(merge_config(given, config, SPRING_FIELDS))
    if "joint_stiffness" not in kwargs:
        raise ParameterError("stiffness", None, "is required (or stiffness_nmm_per_rad in config)")
    return Spring(optimise(SpringRequirement(**kwargs)))


# --------------------------------------------------------------------------- joint


def joint_params(
    *,
    stiffness: float | None = None,
    rotation_deg: float | None = None,
    preload_deg: float | None = None,
    material: str | None = None,
    printer: str | None = None,
    clearance_mm: float | None = None,
    layout: str | None = None,
    arms: int | None = None,
    link_length_mm: float | None = None,
    tendon_diameter_mm: float | None = None,
    tendon_moment_arm_mm: float | None = None,
    pin_radius_mm: float | None = None,
    safety_factor: float | None = None,
    end: str | None = None,
    config: PathLike | None = None,
) -> JointParams:
    """The validated parameters of ``build_joint``'s joint (its spring designed, nothing built): the keywords of
    ``rjcad joint``'s options (None: its default), ``config`` a TOML file of the same keys (keywords win)."""
    from rjcad.design.params import JointParams

    given = from_keywords(
        dict(
            stiffness=stiffness,
            rotation_deg=rotation_deg,
            preload_deg=preload_deg,
            material=material,
            printer=printer,
            clearance_mm=clearance_mm,
            layout=layout,
            arms=arms,
            link_length_mm=link_length_mm,
            tendon_diameter_mm=tendon_diameter_mm,
            tendon_moment_arm_mm=tendon_moment_arm_mm,
            pin_radius_mm=pin_radius_mm,
            safety_factor=safety_factor,
            end=end,
        ),
        JOINT_FIELDS,
    )
    return JointParams(**merge_config(given, config, JOINT_FIELDS))


def build_joint(
    *,
    stiffness: float | None = None,
    rotation_deg: float | None = None,
    preload_deg: float | None = None,
    material: str | None = None,
    printer: str | None = None,
    clearance_mm: float | None = None,
    layout: str | None = None,
    arms: int | None = None,
    link_length_mm: float | None = None,
    tendon_diameter_mm: float | None = None,
    tendon_moment_arm_mm: float | None = None,
    pin_radius_mm: float | None = None,
    safety_factor: float | None = None,
    end: str | None = None,
    config: PathLike | None = None,
) -> Joint:
    """Build the joint module of ``rjcad joint`` (in this process): the keywords of ``joint_params``."""
    p = joint_params(
        stiffness=stiffness,
        rotation_deg=rotation_deg,
        preload_deg=preload_deg,
        material=material,
        printer=printer,
        clearance_mm=clearance_mm,
        layout=layout,
        arms=arms,
        link_length_mm=link_length_mm,
        tendon_diameter_mm=tendon_diameter_mm,
        tendon_moment_arm_mm=tendon_moment_arm_mm,
        pin_radius_mm=pin_radius_mm,
        safety_factor=safety_factor,
        end=end,
        config=config,
    )
    return Joint.from_params(p)


class _Built:
    """What a built joint and a built finger share: manifest, meshes, solids, check."""

    def __init__(self, build: JointBuild | FingerBuild) -> None:
        self._build = build
        self._manifest: Manifest = build.manifest
        self._meshes: dict[str, trimesh.Trimesh] = build.meshes

    @property
    def manifest(self) -> dict[str, Any]:
        """The JSON object of the manifest (``joint.json``, ``finger.json``; a fresh copy)."""
        return _json(self._manifest.to_json())

    @property
    def meshes(self) -> dict[str, trimesh.Trimesh]:
        """The bodies as trimesh meshes, by name [mm] (the files' triangles; copy one before changing it)."""
        return dict(self._meshes)

    @property
    def solids(self) -> dict[str, Any]:
        """The bodies as OpenCASCADE shapes (OCP ``TopoDS_Shape``), by name [mm]."""
        raise NotImplementedError

    def cq_solids(self) -> dict[str, Any]:
        """The bodies as CadQuery shapes (``cadquery.Shape.cast``), by name; needs CadQuery (the extra
        ``rjcad[cadquery]``)."""
        try:
            import cadquery
        except ImportError:
            raise MissingExtra(
                "cq_solids() needs CadQuery, which is not installed: pip install 'rjcad[cadquery]' "
                "(the OCP shapes are in .solids)"
            ) from None
        return {name: cadquery.Shape.cast(s) for name, s in self.solids.items()}

    def check(self, slicer: str | None = None) -> Report:
        """Check the bodies for printing as ``rjcad check`` checks the written mesh with its manifest (the
        manifest's clearance, raised to the printer's minimum gap); ``slicer="prusa"`` also slices them."""
        from rjcad.check import required_clearance, run_checks
        from rjcad.materials import printer_of

        if slicer not in (None, "prusa"):
            raise ParameterError("slicer", slicer, "must be None or 'prusa'")
        man = self._manifest
        clearance = required_clearance(man, printer_of(None, man))
        return run_checks(dict(self._meshes), manifest=man, clearance=clearance, slicer=slicer)


class Joint(_Built):
    """A built joint module: ``params``, ``spring``, ``manifest``, ``meshes`` and ``solids`` (ground, moving)."""

    _build: JointBuild

    @classmethod
    def from_params(cls, params: JointParams) -> Joint:
        """Build the joint of validated ``params`` (``joint_params``, or a ``JointParams`` of your own)."""
        from rjcad.cad.build import build

        return cls(build(params))

    @property
    def params(self) -> JointParams:
        """The parameters it was built from (mm, rad)."""
        return self._build.params

    @property
    def spring(self) -> Spring:
        """Its spring (one of two in the stacked layout)."""
        return Spring(self._build.params.spring)

    @property
    def solids(self) -> dict[str, Any]:
        s = self._build.solids
        assert s is not None  # built in this process
        return {"ground": s.ground, "moving": s.moving}

    def write(self, out_dir: PathLike, *, png: bool = True) -> list[Path]:
        """Write joint.stl, .3mf, .step, .glb, .png (unless ``png`` is False) and .json into ``out_dir``, as one
        set, as ``rjcad joint --out`` does; returns the files written."""
        from rjcad.cad.build import write_joint_files
        from rjcad.io.outputs import check_writable

        check_writable(out_dir)
        return write_joint_files(self._build, Path(out_dir), png=png)

    def __repr__(self) -> str:
        return f"Joint(stiffness={self._build.manifest.joints[0].joint_stiffness_nmm_per_rad:.4g} N·mm/rad)"


# --------------------------------------------------------------------------- finger


def finger_params(
    template: PathLike | Mapping[str, Any] | None = None, *, printer: str | None = None, material: str | None = None
) -> FingerParams:
    """The validated design of a finger (its springs designed, nothing built): a template file (TOML, see
    templates/finger.toml), a dict of the same keys, or None for the default finger (``rjcad finger``'s);
    ``printer`` and ``material`` replace the template's (``rjcad finger --printer --material``)."""
    from rjcad.design.finger_params import FingerParams
    from rjcad.io.templates import DEFAULT_FINGER

    given = {k: v for k, v in (("printer", printer), ("material", material)) if v is not None}
    if template is None:
        return FingerParams.from_dict(DEFAULT_FINGER | given, "built-in finger")
    if isinstance(template, Mapping):
        return FingerParams.from_dict(dict(template) | given)
    try:
        return FingerParams.from_toml(os.fspath(template), given)  # the path as given: the manifest's template
    except ParameterError as e:  # name the file before the key
        name = Path(template).name
        if e.parameter.startswith(f"{name}: "):
            raise
        raise ParameterError(f"{name}: {e.parameter}", e.value, e.limit, e.unit) from None


def build_finger(
    template: PathLike | Mapping[str, Any] | None = None, *, printer: str | None = None, material: str | None = None
) -> Finger:
    """Build the finger of ``rjcad finger`` (in this process): the arguments of ``finger_params``."""
    return Finger.from_params(finger_params(template, printer=printer, material=material))


@dataclass(frozen=True)
class Closure:
    """A simulated pull and release of the tendon, one row per step: ``tendon_mm`` (n,) displacement,
    ``theta_deg`` (n, joints) joint angles, ``tension_n`` (n,) at the actuator, ``joint_tension_n`` (n, joints)
    reaching each joint, ``state`` (n, joints: 0 sticking, 1 closing, -1 opening, 2 on a stop), ``phase``."""

    tendon_mm: np.ndarray
    theta_deg: np.ndarray
    tension_n: np.ndarray
    joint_tension_n: np.ndarray
    state: np.ndarray
    phase: tuple[str, ...]


class Finger(_Built):
    """A built finger: ``params``, ``manifest``, ``meshes`` and ``solids`` (base, link1, …, distal)."""

    _build: FingerBuild

    @classmethod
    def from_params(cls, params: FingerParams) -> Finger:
        """Build the finger of validated ``params`` (``finger_params``)."""
        from rjcad.cad.build import build_finger_model

        return cls(build_finger_model(params))

    @property
    def params(self) -> FingerParams:
        """The design it was built from (mm, rad)."""
        return self._build.params

    @property
    def solids(self) -> dict[str, Any]:
        return dict(self._build.solids)

    def write(self, out_dir: PathLike, *, png: bool = True, html: bool = False) -> list[Path]:
        """Write finger.stl, .3mf, .step, .glb, .png (unless ``png`` is False), .json and with ``html`` the viewer
        finger.html into ``out_dir``, as one set, as ``rjcad finger --out`` does; returns the files written."""
        from rjcad.cad.build import write_finger_files
        from rjcad.io.outputs import check_writable
        from rjcad.view import finger_page, vendored_three

        check_writable(out_dir)
        if html:
            vendored_three()  # a missing three.js is said before the files are made
        return write_finger_files(self._build, Path(out_dir), png=png, more=finger_page if html else None)

    def simulate(
        self, stroke_mm: float = FINGER.stroke, steps: int = 500, mu_t: float = 0.0, bearing_mu: float | None = None
    ) -> Closure:
        """Pull the tendon from 0 to ``stroke_mm`` in ``steps`` steps, then release it, as ``rjcad simulate finger``
        on the manifest (measured arms and wraps; ``mu_t``: the tendon's friction coefficient on its path;
        ``bearing_mu``: each joint's friction from its own bearing at this μ, ``--friction bearing --mu``)."""
        from rjcad.physics.finger import model_from_manifest, simulate_stroke
        from rjcad.validate import in_range

        in_range("stroke_mm", stroke_mm, 0.0, MAX_STROKE_MM, lo_open=True, unit="mm")
        in_range("mu_t", mu_t, 0.0, MAX_MU_T)
        if isinstance(steps, bool) or not isinstance(steps, int):
            raise ParameterError("steps", steps, "must be an integer")
        in_range("steps", steps, *STEPS)
        model = _with_bearing(model_from_manifest(self._build.manifest, mu_t=mu_t), self.params.joints, bearing_mu)
        c = simulate_stroke(model, float(stroke_mm), steps=steps)
        return Closure(
            c.tendon_mm, np.degrees(c.theta), c.tension, c.joint_tension, c.state.astype(int), tuple(c.phase)
        )

    def grasp(
        self,
        objects: Object | Sequence[Object],
        *,
        max_tension_n: float = 10.0,
        stroke_mm: float | None = None,
        steps: int = 40,
        engine: str = "rjcad",
        mu_t: float = 0.0,
        bearing_mu: float | None = None,
    ) -> Grasp:
        """Close this finger on ``objects`` (``Cylinder``, ``Box``) as ``rjcad simulate finger finger.json
        --object``: the tension ramped from 0 to ``max_tension_n`` [N] in ``steps`` readings (stopped at
        ``stroke_mm`` of tendon travel if given), by ``engine`` ("rjcad" or "mujoco"), the links' outlines from
        the manifest where it has them; ``bearing_mu`` as in ``simulate`` (rjcad's engine); returns a ``Grasp``
        (``verdict()``, ``to_dict()``)."""
        from rjcad.physics.finger import model_from_manifest
        from rjcad.physics.grasp_run import base_outline_of, grasp_outlines_of

        model = model_from_manifest(self._build.manifest, mu_t=mu_t)
        model = _with_bearing(model, self.params.joints, bearing_mu, engine)
        manifest = self._build.manifest.to_json()
        outlines = grasp_outlines_of(manifest, model)
        return _grasp(
            model, objects, outlines, max_tension_n, stroke_mm, steps, engine, None, base_outline_of(manifest)
        )

    def __repr__(self) -> str:
        return f"Finger({self.params.n} joints, source={self.params.source!r})"


# --------------------------------------------------------------------------- grasp


def Box(
    x: float, y: float, w: float, h: float, *, angle_deg: float = 0.0, mu: float = 0.0, free: bool = False,
    mass_g: float = 0.0,
) -> _Box:  # fmt: skip
    """A box object: centre (``x``, ``y``) [mm] in the finger base's frame, ``w`` × ``h`` [mm], turned by
    ``angle_deg`` about +z; ``mu`` its contact friction; ``free`` with a mass ``mass_g`` [g], or fixed."""
    import math

    from rjcad.validate import in_range

    in_range("angle_deg", angle_deg, -720.0, 720.0)
    return _Box(x, y, w, h, angle=math.radians(angle_deg), mu=mu, free=free, mass_g=mass_g)


def grasp(
    source: PathLike | None,
    objects: Object | Sequence[Object] = (),
    *,
    max_tension_n: float = 10.0,
    stroke_mm: float | None = None,
    steps: int = 40,
    engine: str = "rjcad",
    mu_t: float = 0.0,
    bearing_mu: float | None = None,
) -> Grasp:
    """Close a finger given by a file, without building it, as ``rjcad simulate finger SOURCE --object``: a
    manifest (.json: its outlines) or a template (.toml: its ``[[object]]`` tables too), None for the paper's
    finger; the other arguments as ``Finger.grasp``."""
    from rjcad.physics.finger_sources import load_finger_designs
    from rjcad.physics.grasp_run import grasp_model, grasp_outlines, template_objects

    path = None if source is None else os.fspath(source)
    model = grasp_model(path, mu_t)
    if bearing_mu is not None:
        model = _with_bearing(model, load_finger_designs(path), bearing_mu, engine)
    given = [objects] if isinstance(objects, (Cylinder, _Box)) else list(objects)
    both = [*template_objects(path), *given]
    return _grasp(model, both, grasp_outlines(path, model), max_tension_n, stroke_mm, steps, engine, path)


def _with_bearing(model: Any, joints: Sequence[JointParams], mu: float | None, engine: str = "rjcad") -> Any:
    """``model`` with each joint's friction band from its bearing at ``mu`` (``bearing_mu``; None: unchanged)."""
    if mu is None:
        return model
    from rjcad.physics.bearing_band import JointLocked, with_bearing_friction
    from rjcad.validate import in_range

    if engine != "rjcad":
        raise ParameterError("bearing_mu", mu, "rjcad's engine only: MuJoCo's joint friction is a constant")
    in_range("bearing_mu", mu, 0.0, 2.0)
    try:
        return with_bearing_friction(model, joints, mu)[0]
    except JointLocked as e:
        raise e.parameter_error("bearing_mu", mu) from None


def _grasp(
    model: Any,
    objects: Object | Sequence[Object],
    outlines: Any,
    max_tension_n: float,
    stroke_mm: float | None,
    steps: int,
    engine: str,
    source: str | None,
    base_outline: Any = None,
) -> Grasp:
    """``run_grasp`` with the API's checks: the objects are ``Cylinder`` or ``Box``, ``steps`` an integer."""
    from rjcad.physics.grasp_run import run_grasp
    from rjcad.validate import in_range

    objs = [objects] if isinstance(objects, (Cylinder, _Box)) else list(objects)
    for k, o in enumerate(objs, start=1):
        if not isinstance(o, (Cylinder, _Box)):
            raise ParameterError(f"objects[{k}]", o, "must be a Cylinder or a Box (rjcad.api)")
    if isinstance(steps, bool) or not isinstance(steps, int):
        raise ParameterError("steps", steps, "must be an integer")
    in_range("steps", steps, 2, STEPS[1])
    return run_grasp(
        engine, model, objs, max_tension_n=max_tension_n, stroke=stroke_mm, outlines=outlines, steps=steps,
        source=source, base_outline=base_outline,
    )  # fmt: skip
