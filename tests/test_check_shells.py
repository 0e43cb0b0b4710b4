"""The motion sweep's screen (rjcad.check.shells) proves poses free without changing a verdict.

Checked against what does not share its reasoning: the (r, z) boxes against points sampled on the surface, and
the whole sweep against intersecting every pose on the bodies (what the sweep did before it had a screen), on
hinges with obstacles that hit the arm, graze it, or miss it by less than a pose step."""

import math

import manifold3d as m3
import numpy as np
import pytest
import trimesh
from mesh_tools import box, cyl, difference, manifold, union
from test_check import hinge

from rjcad.check.copies import APART_MM, Copies, min_gap
from rjcad.check.motion import _rot, sweep_joint
from rjcad.check.shells import axis_frame, facing, rz_boxes, shells
from rjcad.io.manifest import JointEntry
from rjcad.materials import get_printer

PRINTER = get_printer("generic-0.4")


def _rz(points: np.ndarray, point, direction) -> np.ndarray:
    local = points @ axis_frame(point, direction)[:, :3].T + axis_frame(point, direction)[:, 3]
    return np.column_stack([np.hypot(local[:, 0], local[:, 1]), local[:, 2]])


@pytest.mark.parametrize(
    "shape",
    [
        trimesh.creation.cone(radius=6.0, height=9.0, sections=24),  # slanted faces: split until thin
        trimesh.creation.box(extents=(8.0, 3.0, 5.0)),  # walls along and across the axis
        trimesh.creation.icosphere(subdivisions=2, radius=4.0),
        trimesh.creation.annulus(r_min=3.0, r_max=5.0, height=4.0, sections=16),
    ],
)
@pytest.mark.parametrize("axis", [((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)), ((2.0, -1.0, 3.0), (0.3, 0.9, 0.2))])
def test_rz_boxes_hold_every_point_of_the_surface(shape, axis):
    point, direction = axis
    boxes = rz_boxes(manifold(shape).transform(axis_frame(point, direction)))
    samples, _ = trimesh.sample.sample_surface(shape, 4000, seed=3)
    rz = _rz(np.vstack([samples, shape.vertices]), point, direction)
    eps = 1e-9
    inside = (
        (rz[:, None, 0] >= boxes[None, :, 0] - eps)
        & (rz[:, None, 0] <= boxes[None, :, 1] + eps)
        & (rz[:, None, 1] >= boxes[None, :, 2] - eps)
        & (rz[:, None, 1] <= boxes[None, :, 3] + eps)
    )
    assert inside.any(axis=1).all()


def _exhaustive(ground: m3.Manifold, moving: m3.Manifold, angles) -> tuple[float, float | None, float | None]:
    """(worst overlap, its angle, first contact angle): every pose intersected on the bodies."""
    worst, at, first = 0.0, None, None
    for a in angles:
        vol = (ground ^ moving.transform(_rot((0, 0, 0), (0, 0, 1), float(a)))).volume()
        if vol > worst:
            worst, at = vol, float(a)
        if vol > 0 and first is None:
            first = float(a)
    return worst, at, first


def _post(r: float, angle_deg: float, size: float, top: float) -> trimesh.Trimesh:
    """A square post on the plate (from z 1), centred at radius r [mm] and angle [deg], up to z = top."""
    post = box((r - size / 2, -size / 2, 1.0), (r + size / 2, size / 2, top))
    post.apply_transform(trimesh.transformations.rotation_matrix(math.radians(angle_deg), (0, 0, 1)))
    return post


def _obstacles():
    """(name, obstacle on the ground, rotation [deg]): the arm (r 5 to 16.12 at its corners, z 2.4 to 12, 4 mm
    wide) hits it at some angle, grazes it, or passes it closer than one pose step moves a point."""
    rng = np.random.default_rng(7)
    cases = []
    for n in range(6):  # random posts: tall ones in the arm's path or beyond its range, low ones under it
        top = float(rng.choice([rng.uniform(4.0, 13.0), 2.3]))  # 2.3: 0.1 mm under the arm, passed at every angle
        cases.append((f"post {n}", _post(rng.uniform(7.0, 15.0), rng.uniform(30, 130), 1.5, top), 90.0))
    cases.append(("post past the tip", _post(16.125 + 0.05 + 0.75, 45.0, 1.5, 13.0), 90.0))
    cases.append(("post at the tip's corner", _post(16.125 - 0.05 + 0.75, 45.0, 1.5, 13.0), 90.0))
    cases.append(("ring clear of the tip", difference(cyl(18.0, 3.0, 11.0), cyl(16.2, 2.0, 12.0)), 180.0))
    cases.append(("ring in the tip's way", difference(cyl(18.0, 3.0, 11.0), cyl(16.1, 2.0, 12.0)), 30.0))
    wall = box((6.0, 2.03, 3.0), (17.0, 3.0, 11.0))  # across the arm's path, 0.03 mm beyond its last pose
    wall.apply_transform(trimesh.transformations.rotation_matrix(math.radians(60), (0, 0, 1)))
    cases.append(("wall just past the range", wall, 60.0))
    return cases


@pytest.mark.parametrize("case", _obstacles(), ids=lambda c: c[0])
def test_sweep_gives_what_every_pose_gives(case):
    _, post, rotation = case
    h = hinge()
    bodies = {"ground": union(h["ground"], post), "moving": h["moving"]}
    meshes = list(bodies.values())
    mans = [manifold(m) for m in meshes]
    joint = JointEntry(
        parent="ground", child="moving", axis_point_mm=[0, 0, 0], axis_dir=[0, 0, 1], rotation_deg=rotation
    )
    copies = Copies(list(mans), list(mans), list(mans))  # the exact path: nothing simplified
    (vol, at, _), first, (gap, _), detail = sweep_joint(0, [joint], meshes, list(bodies), mans, 0.25, PRINTER, copies)
    poses = int(detail.split(" poses")[0].split()[-1])
    angles = np.linspace(0.0, math.radians(rotation), poses)
    worst, worst_at, first_ref = _exhaustive(mans[0], mans[1], angles)
    assert (vol, at, first) == (worst, worst_at, first_ref)
    every = max(1, poses // 24)
    sampled = [a for i, a in enumerate(angles) if i % every == 0 or i == poses - 1]
    gaps = [
        0.0
        if (mans[0] ^ mans[1].transform(_rot((0, 0, 0), (0, 0, 1), float(a)))).volume() > 0
        else mans[0].min_gap(mans[1].transform(_rot((0, 0, 0), (0, 0, 1), float(a))), 1.25)
        for a in sampled
    ]
    assert gap == pytest.approx(min(gaps), abs=1e-9)


def test_shells_leave_out_only_what_stays_apart():
    """Points of the arm outside every shell stay farther than the margin from the ground at every angle."""
    h = hinge()
    ground, moving = manifold(h["ground"]), manifold(h["moving"])
    shl = shells(moving, ground, (0, 0, 0), (0, 0, 1), APART_MM, 0.05)
    kept = m3.Manifold.batch_boolean([s.turning for s in shl], m3.OpType.Add)
    rest = moving - kept
    for a in np.linspace(0.0, 2 * math.pi, 73):
        posed = rest.transform(_rot((0, 0, 0), (0, 0, 1), float(a)))
        assert ground.min_gap(posed, 1.0) > APART_MM
    for s in shl:  # each shell's still part holds all the ground within its reach
        far = ground - s.still
        for a in np.linspace(0.0, 2 * math.pi, 37):
            assert (
                far.min_gap(s.turning.transform(_rot((0, 0, 0), (0, 0, 1), float(a))), 2.0) > APART_MM + 0.05 * s.lever
            )


def test_facing_keeps_every_gap_within_its_margin():
    h = hinge(obstacle=True)
    ground, moving = manifold(h["ground"]), manifold(h["moving"])
    near_moving, near_ground = facing(moving, ground, (0, 0, 0), (0, 0, 1), 1.25)
    for a in np.linspace(0.0, math.radians(50), 11):
        t = _rot((0, 0, 0), (0, 0, 1), float(a))
        assert min_gap(near_ground, near_moving.transform(t), 1.25) == pytest.approx(
            min_gap(ground, moving.transform(t), 1.25), abs=1e-12
        )
