"""The simplified copies (rjcad.check.copies) change no verdict and no number beyond their stated tolerance.

The other check tests use meshes that simplifying does not halve, so they run the exact path (each pose
intersected on the bodies). Here the same parts are refined (each triangle split at its edge midpoints: the
same shape, 4× the triangles) or tessellated finer than the coarse tolerance, so that the copies are used, and
the reports are compared with the exact path on the same mesh."""

import pytest
import trimesh
from mesh_tools import box, manifold, union
from test_check import hinge, manifest_for

from rjcad.check import check_clearance, check_motion
from rjcad.check.copies import APART_MM, FINE_TOL_MM, Copies, near, simplified
from rjcad.materials import get_printer

PRINTER = get_printer("generic-0.4")
GAP_TOL = 2 * FINE_TOL_MM  # reported gaps: fine copies within FINE_TOL_MM of their bodies


def refined(mesh: trimesh.Trimesh, levels: int = 1) -> trimesh.Trimesh:
    v, f = mesh.vertices, mesh.faces
    for _ in range(levels):
        v, f = trimesh.remesh.subdivide(v, f)
    return trimesh.Trimesh(v, f, process=False)


def exact(mans) -> Copies:
    """Copies that are the bodies themselves: the exact path."""
    return Copies(list(mans), list(mans), list(mans))


def reports(bodies: dict, motion: bool = True):
    """(clearance, motion) on the exact path, then on the simplified copies; and the copies."""
    names, meshes = list(bodies), list(bodies.values())
    mans = [manifold(m) for m in meshes]
    man = manifest_for(bodies)
    out = []
    for copies in (exact(mans), simplified(mans)):
        out.append(
            (
                check_clearance(meshes, names, mans, 0.25, 0.02, copies),
                check_motion(meshes, names, mans, man, 0.25, PRINTER, copies) if motion else None,
            )
        )
    return out, copies


def same(a, b):
    """Same verdict, location and detail; values equal, or gaps within GAP_TOL."""
    assert a.passed == b.passed and a.where == b.where, (a, b)
    if isinstance(a.value, float) and a.passed is not False:
        assert abs(a.value - b.value) <= GAP_TOL + 1e-4, (a.value, b.value)  # values are rounded to 0.1 µm
    else:
        assert a.value == b.value and a.detail == b.detail, (a, b)


@pytest.mark.slow  # whole sweeps on 4× refined meshes, twice
@pytest.mark.parametrize("obstacle", [False, True])
def test_refined_hinge_gives_the_exact_paths_report(obstacle):
    bodies = {k: refined(m) for k, m in hinge(obstacle).items()}
    ((c0, m0), (c1, m1)), copies = reports(bodies)
    assert all(c.num_tri() * 2 < b.num_tri() for c, b in zip(copies.coarse, copies.bodies))  # the copies are used
    same(c0, c1)
    same(m0, m1)
    assert m1.passed is (not obstacle)
    if obstacle:  # the colliding poses are intersected on the bodies: the same worst pose and overlap
        assert "collides" in m1.detail and m0.detail == m1.detail


def test_refined_overlap_is_measured_on_the_bodies():
    b = hinge()
    b["moving"] = b["moving"].copy()
    b["moving"].apply_translation((0.5, 0, 0))  # the tube's bore (r 2.25) now cuts into the pin (r 2)
    bodies = {k: refined(m) for k, m in b.items()}
    ((c0, _), (c1, _)), _ = reports(bodies, motion=False)
    assert c0.passed is False and "overlap by" in c1.detail
    assert c0.detail == c1.detail and c0.where == c1.where


@pytest.mark.slow
def test_a_fine_tessellation_is_screened_on_its_coarse_copy():
    """A pin of 4096 sections (sagitta 0.03 µm): the fine copy keeps most of it, the coarse one does not."""
    pin = trimesh.creation.cylinder(radius=2.0, height=14, sections=4096)
    pin.apply_translation((0, 0, 7))
    bodies = {"ground": union(box((-12, -12, 0), (12, 12, 2)), pin), "moving": hinge()["moving"]}
    ((c0, m0), (c1, m1)), copies = reports(bodies)
    assert copies.coarse[0] is not copies.fine[0]  # the coarse tier is in use
    same(c0, c1)
    same(m0, m1)


def test_copies_apart_prove_the_bodies_apart():
    """Refined cubes side by side: their coarse copies are near exactly when the cubes are within APART_MM."""
    a = refined(trimesh.creation.box(extents=(10, 10, 10)))
    for gap, close in ((0.05, False), (APART_MM / 2, True), (-0.01, True)):
        b = a.copy()
        b.apply_translation((10 + gap, 0, 0))
        ca, cb = simplified([manifold(a), manifold(b)]).coarse
        assert near(ca, cb) is close, gap
