"""Issue #16: `rjcad check` never passes a broken mesh and does not cry wolf on a sound one.

A sound two-body print-in-place part (a pin with a pointed tip in a tube with an arm, and a comb of two walls
0.6 mm apart, all made here from trimesh/manifold3d primitives) is damaged one way at a time; each damaged file, written as STL and as
3MF, must fail the named check with `where` within 1 mm of the damage, and the sound part must pass every check.
Sound parts with creases, fillets, chamfers, a countersink, a near-tangent union, a cone's tip and a chamfer's
knife-edge end pass watertight and min_feature.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from mesh_tools import box, cyl, difference, union

from rjcad.cad import mesh_export as mx
from rjcad.check import run_checks

SEG = 192
CLEARANCE = 0.25


def comb(slot=0.6, wall=1.2):
    """Two walls ``wall`` thick, ``slot`` apart, standing on the plate at x −10..−4 (a coil gap's stand-in)."""
    y0 = -11.0
    return union(box((-10, y0, 2), (-4, y0 + wall, 8)), box((-10, y0 + wall + slot, 2), (-4, y0 + 2 * wall + slot, 8)))


def pin():
    """The pin: r 2, z 0 … 14, with a 20° cone on top narrowing to a point (a tip, no thin wall)."""
    tip = trimesh.creation.cone(radius=2.0, height=2.0 / np.tan(np.radians(20)), sections=SEG)
    tip.apply_translation((0, 0, 14.0))
    return union(cyl(2.0, 0, 14, sections=SEG), tip)


def part(slot=0.6, wall=1.2):
    """ground: plate + pin r 2 with a pointed tip + comb; moving: a tube (bore r 2.25) with an arm along +X."""
    ground = union(box((-12, -12, 0), (12, 12, 2)), pin(), comb(slot, wall))
    tube = difference(cyl(5.0, 2.4, 12, sections=SEG), cyl(2.25, 2.0, 12.5, sections=SEG))
    moving = union(tube, box((4, -2, 2.4), (16, 2, 12)))
    return {"ground": ground, "moving": moving}


# ---------------------------------------------------------------- mutations: (bodies) -> (bodies, damage point)


def tri_samples(tri, n=12):
    """Points over a triangle (and its edges) [mm]."""
    a, b, c = np.asarray(tri)
    return np.array([a + (b - a) * i / n + (c - a) * j / n for i in range(n + 1) for j in range(n + 1 - i)])


def seg_samples(a, b, n=50):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a + (b - a) * np.linspace(0, 1, n)[:, None]


def _nearest_face(m, point):
    return int(np.argmin(np.linalg.norm(m.triangles_center - np.asarray(point), axis=1)))


def _edit(m, faces=None, vertices=None):
    return trimesh.Trimesh(
        m.vertices if vertices is None else vertices, m.faces if faces is None else faces, process=False
    )


def delete_triangle(b):
    g = b["ground"]
    i = _nearest_face(g, (8.0, 8.0, 2.0))  # on the plate's top
    return {**b, "ground": _edit(g, faces=np.delete(g.faces, i, axis=0))}, tri_samples(g.triangles[i])


def delete_patch(b):
    m = b["moving"]
    at = np.array([0.0, 5.0, 7.0])  # the tube's outside, opposite the arm
    keep = np.linalg.norm(m.triangles_center - at, axis=1) > 1.5
    assert (~keep).sum() >= 3
    return {**b, "moving": _edit(m, faces=m.faces[keep])}, np.vstack([tri_samples(t) for t in m.triangles[~keep]])


def flip_face(b):
    g = b["ground"]
    i = _nearest_face(g, (0.0, 2.0, 8.0))  # on the pin
    f = g.faces.copy()
    f[i] = f[i][::-1]
    return {**b, "ground": _edit(g, faces=f)}, tri_samples(g.triangles[i])


def flip_body(b):
    m = b["moving"]
    return {**b, "moving": _edit(m, faces=m.faces[:, ::-1])}, m.vertices


def duplicate_face(b):
    g = b["ground"]
    i = _nearest_face(g, (-8.0, 8.0, 2.0))
    return {**b, "ground": _edit(g, faces=np.vstack([g.faces, g.faces[i]]))}, tri_samples(g.triangles[i])


def degenerate_triangle(b):
    """A zero-area triangle on an existing edge: the edge's two ends and its midpoint (a new vertex)."""
    g = b["ground"]
    i = _nearest_face(g, (8.0, -8.0, 2.0))
    a, c = g.faces[i][0], g.faces[i][1]
    mid = (g.vertices[a] + g.vertices[c]) / 2
    v = np.vstack([g.vertices, mid])
    return (
        {**b, "ground": _edit(g, faces=np.vstack([g.faces, [a, c, len(v) - 1]]), vertices=v)},
        seg_samples(g.vertices[a], g.vertices[c]),
    )


def poke_vertex(b):
    """One vertex of the tube's bore moved 0.5 mm inwards, into the pin."""
    m = b["moving"]
    r = np.hypot(m.vertices[:, 0], m.vertices[:, 1])
    bore = np.flatnonzero((np.abs(r - 2.25) < 1e-3) & (m.vertices[:, 2] > 11.9))  # the bore's top rim
    k = int(bore[0])
    v = m.vertices.copy()
    v[k, :2] *= (2.25 - 0.5) / 2.25
    return {**b, "moving": _edit(m, vertices=v)}, v[k][None, :]


def shift_overlap(b):
    """The moving body 0.30 mm along +X: the bore overlaps the pin by 0.05 mm at x = −2."""
    m = b["moving"].copy()
    m.apply_translation((0.30, 0, 0))
    return {**b, "moving": m}, seg_samples((-2.0, 0.0, 2.4), (-2.0, 0.0, 12.0))


def shift_gap(b):
    """The moving body 0.15 mm along +X: 0.10 mm between bore and pin at x = −2."""
    m = b["moving"].copy()
    m.apply_translation((0.15, 0, 0))
    return {**b, "moving": m}, seg_samples((-2.0, 0.0, 2.4), (-2.0, 0.0, 12.0))


def thin_wall(b):
    """The comb's first wall 0.2 mm thick."""
    return part(wall=1.2) | {
        "ground": union(
            box((-12, -12, 0), (12, 12, 2)),
            pin(),
            box((-10, -11, 2), (-4, -10.8, 8)),
            box((-10, -10.2, 2), (-4, -9.0, 8)),
        )
    }, np.array([(x, y, z) for x in np.linspace(-10, -4, 13) for y in (-11.0, -10.8) for z in np.linspace(2, 8, 13)])


def close_gap(b):
    """The comb's slot 0.1 mm wide."""
    return part(slot=0.1), np.array(
        [(x, y, z) for x in np.linspace(-10, -4, 13) for y in (-9.8, -9.7) for z in np.linspace(2, 8, 13)]
    )


MUTATIONS = [
    (delete_triangle, "watertight"),
    (delete_patch, "watertight"),
    (flip_face, "watertight"),
    (flip_body, "watertight"),
    (duplicate_face, "watertight"),
    (degenerate_triangle, "watertight"),
    (poke_vertex, "clearance"),
    (shift_overlap, "clearance"),
    (shift_gap, "clearance"),
    (thin_wall, "min_feature"),
    (close_gap, "min_feature"),
]


@pytest.fixture(scope="module")
def sound():
    return part()


def write(tmp_path, bodies, fmt):
    path = tmp_path / f"part.{fmt}"
    if fmt == "stl":
        path.write_bytes(mx.stl_bytes(list(bodies.values())))
    else:
        path.write_bytes(mx.threemf_bytes(bodies, "part"))
    return path


def check(path, n=2):
    return run_checks(str(path), clearance=CLEARANCE, printer="generic-0.4", bodies=n)


@pytest.mark.parametrize("fmt", ["stl", "3mf"])
def test_the_sound_part_passes_every_check(sound, tmp_path, fmt):
    rep = check(write(tmp_path, sound, fmt))
    # (it is not support-free: the tube starts 0.4 mm over the plate, which `overhang` rightly reports)
    bad = {c.name: c.detail for c in rep.checks if c.passed is False and c.name != "overhang"}
    assert not bad, bad
    assert {"watertight", "manifold", "bodies", "clearance", "min_feature", "bed"} <= {
        c.name for c in rep.checks if c.passed
    }


@pytest.mark.parametrize("fmt", ["stl", "3mf"])
@pytest.mark.parametrize("mutate, name", MUTATIONS, ids=[m.__name__ for m, _ in MUTATIONS])
def test_each_mutation_fails_the_right_check_at_the_damage(sound, tmp_path, fmt, mutate, name):
    bodies, at = mutate(sound)
    rep = check(write(tmp_path, bodies, fmt))
    c = rep.get(name)
    assert c.passed is False, (name, c.detail)
    assert c.where is not None, c.detail
    dist = float(np.min(np.linalg.norm(np.asarray(at, float).reshape(-1, 3) - np.asarray(c.where), axis=1)))
    assert dist <= 1.0, (c.where, dist, c.detail)  # (inside out: the damage is the whole body, any of its points)


# ---------------------------------------------------------------- sound shapes that must not cry wolf


def crease():
    """A ring with a box cutting slightly into its outside (a shallow re-entrant V at the union)."""
    ring = difference(cyl(6.0, 0, 5, sections=SEG), cyl(4.0, -1, 6, sections=SEG))
    return union(ring, box((5.6, -2, 0), (12, 2, 5)))


def fillet():
    """A block with a rounded (r 2) vertical edge: the box minus the corner plus a quarter cylinder."""
    body = union(box((0, 0, 0), (8, 8, 5)), box((8, 2, 0), (10, 8, 5)), cyl(2.0, 0, 5, 8, 2, sections=SEG))
    return body


def chamfer():
    pts = np.array(
        [(x, y, z) for x in (0, 10) for y in (0, 10) for z in (0, 4)] + [(1, 1, 5), (9, 1, 5), (1, 9, 5), (9, 9, 5)],
        float,
    )
    pts = pts[pts[:, 2] != 4]
    return trimesh.convex.convex_hull(np.vstack([pts, [(0, 0, 4), (10, 0, 4), (0, 10, 4), (10, 10, 4)]]))


def countersink():
    plate = box((-8, -8, 0), (8, 8, 4))
    cone = trimesh.creation.cone(radius=3.4, height=3.4, sections=SEG)  # 45° sink, tip down
    cone.apply_transform(trimesh.transformations.rotation_matrix(np.pi, [1, 0, 0]))
    cone.apply_translation((0, 0, 4.0 + 3.4 - 1.7))
    return difference(plate, union(cyl(1.7, -1, 5, sections=SEG), cone))


def near_tangent():
    """A cylinder fused to a block it overlaps by 0.1 mm (a tangent-ish CAD union: the crease opens at 15°;
    min_feature counts a gap only across faces within 10° of facing each other, so a crease sharper than
    that, e.g. a 0.02 mm overlap at 6.6°, would still be reported as a gap)."""
    return union(box((0, -5, 0), (10, 5, 6)), cyl(3.0, 0, 6, -2.9, 0, sections=SEG))


def cone_tip(half_angle=20.0):
    """A post r 3 with a cone on top narrowing to a point (``half_angle`` from its axis): the last 0.7 mm of a
    20° tip are thinner than the minimum wall, and the nozzle prints it as far as it can (no thin wall)."""
    height = 3.0 / np.tan(np.radians(half_angle))
    tip = trimesh.creation.cone(radius=3.0, height=height, sections=SEG)
    tip.apply_translation((0, 0, 5.0))
    return union(cyl(3.0, 0, 5.0, sections=SEG), tip)


def chamfer_end():
    """A block whose end is chamfered top and bottom to a knife edge (a chamfer's end, 14° each side)."""
    pts = [
        (0, 0, 0),
        (10, 0, 0),
        (0, 10, 0),
        (10, 10, 0),
        (0, 0, 4),
        (0, 10, 4),
        (10, 0, 4),
        (10, 10, 4),
        (18, 0, 2),
        (18, 10, 2),
    ]
    return trimesh.convex.convex_hull(np.array(pts, float))


SOUND_SHAPES = [crease, fillet, chamfer, countersink, near_tangent, cone_tip, chamfer_end]


@pytest.mark.parametrize("fmt", ["stl", "3mf"])
@pytest.mark.parametrize("make", SOUND_SHAPES, ids=[m.__name__ for m in SOUND_SHAPES])
def test_sound_shapes_pass_watertight_and_min_feature(tmp_path, fmt, make):
    rep = check(write(tmp_path, {"part": make()}, fmt), n=1)
    for name in ("watertight", "manifold", "min_feature"):
        c = rep.get(name)
        assert c.passed is True, (name, c.detail)
