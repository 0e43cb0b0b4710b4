"""The overhang check: every downward-facing surface of every body, by what holds it up in print.

A facet faces down when it is flatter than 45° from horizontal with its normal pointing down
(n_z < −cos 45°). Facets on z ≈ 0 are on the bed. The others are sampled at the centres of an XY
grid of ``cell`` mm (finer than the printer's minimum gap), and each sample is classified:

- ``other body``: a ray straight down meets another body less than OPEN_BELOW_MM below: the first
  layer over it sags onto that body, or is printed on it across a flat gap;
- ``anchored``: its own body holds it: it lies on a straight chord ≤ MAX_BRIDGE_MM across its
  downward region whose two ends land on the body's material half a layer lower (a bridge), or
  it lies within half a nozzle of such material (a lip one road covers);
- ``air``: anything else: a cantilever, a bridge too long or anchored at one end, a surface that
  no edge of its body holds ("starts in mid-air"), and lowest points (a cone's tip, a knife edge)
  with nothing of their body below.

A region is the samples joined by grid steps (4-neighbours) whose heights differ by less than a
cell, i.e. one surface flatter than 45°; since the cell is finer than the minimum gap, no region
jumps a gap. As a slicer does, a region is bridged in one direction: the one of 8 (every 22.5°)
that anchors most of its samples. The worst place is the failing sample farthest from its body's
support along its region (a region with no anchor counts its whole extent): how far the printer
would lay filament on nothing. Areas are projected on the bed (what a layer prints), in mm².
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, dijkstra

from rjcad.check.report import CheckResult, point
from rjcad.materials import Printer

#: A facet flatter than this from horizontal, facing down, is an overhang [rad].
OVERHANG_ANGLE = math.radians(45.0)
#: Longest bridge between two anchors of the same body [mm] (issue #15's rule).
MAX_BRIDGE_MM = 10.0
#: Open space a surface needs above another body, or it prints onto it [mm].
OPEN_BELOW_MM = 2.0
#: A facet whose vertices all lie within this of z = 0 is on the bed [mm].
BED_TOL_MM = 0.01
#: Bridge directions tried per region (every 180°/n).
BRIDGE_DIRECTIONS = 8
CATEGORIES = ("bed", "anchored", "other body", "air")
_STEPS4 = ((1, 0), (0, 1))
_STEPS8 = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1))


def grid_cell(printer: Printer) -> float:
    """Sample spacing [mm]: 0.25, or 0.8 × the printer's minimum gap if finer (no region jumps a gap)."""
    return min(0.25, 0.8 * printer.min_gap_mm)


def _raster(tris: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid cells (i, j) whose centre ((i + ½)·cell, (j + ½)·cell) lies in a triangle's XY shadow; z there.

    Scan lines: each grid row a triangle spans is cut by its edges into one x interval.
    """
    uv = tris[:, :, :2] / cell - 0.5  # grid units: cell centres at integers
    j0 = np.ceil(uv[:, :, 1].min(axis=1) - 1e-9).astype(np.int64)
    rows = np.maximum(np.floor(uv[:, :, 1].max(axis=1) + 1e-9).astype(np.int64) - j0 + 1, 0)
    k = np.repeat(np.arange(len(tris)), rows)
    gj = j0[k] + np.arange(int(rows.sum())) - np.repeat(np.cumsum(rows) - rows, rows)
    lo, hi = np.full(len(k), np.inf), np.full(len(k), -np.inf)
    for e in range(3):
        p, q = uv[k, e], uv[k, (e + 1) % 3]
        dy = q[:, 1] - p[:, 1]
        flat = np.abs(dy) < 1e-12
        f = np.where(flat, 0.0, (gj - p[:, 1]) / np.where(flat, 1.0, dy))
        cut = ~flat & (f >= -1e-9) & (f <= 1 + 1e-9)
        x = p[:, 0] + f * (q[:, 0] - p[:, 0])
        on = flat & (np.abs(p[:, 1] - gj) < 1e-9)
        for xs, m in ((x, cut), (p[:, 0], on), (q[:, 0], on)):
            lo = np.where(m, np.minimum(lo, xs), lo)
            hi = np.where(m, np.maximum(hi, xs), hi)
    i0 = np.ceil(lo - 1e-9)
    n = np.where(np.isfinite(lo), np.floor(hi + 1e-9) - i0 + 1, 0).clip(min=0).astype(np.int64)
    kk = np.repeat(k, n)
    gi = np.repeat(i0, n).astype(np.int64) + np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    gj = np.repeat(gj, n)
    if not len(gi):
        return gi, gj, np.zeros(0)
    v0 = tris[kk, 0]
    nrm = np.cross(tris[kk, 1] - v0, tris[kk, 2] - v0)
    x, y = (gi + 0.5) * cell, (gj + 0.5) * cell
    z = v0[:, 2] - (nrm[:, 0] * (x - v0[:, 0]) + nrm[:, 1] * (y - v0[:, 1])) / nrm[:, 2]
    zq = np.round(z / 1e-3).astype(np.int64)
    a, b, c = gi - gi.min(), gj - gj.min(), zq - zq.min()
    _, first = np.unique((a * (b.max() + 1) + b) * (c.max() + 1) + c, return_index=True)
    return gi[first], gj[first], z[first]


class _Grid:
    """Samples on the grid, and lookup of a sample's neighbour in a given grid step."""

    def __init__(self, gi: np.ndarray, gj: np.ndarray, z: np.ndarray):
        self.gi, self.gj, self.z = gi, gj, z
        self.span = int(gj.max() - gj.min() + 3) if len(gj) else 1
        self.key = (gi - (gi.min() if len(gi) else 0)) * self.span + (gj - (gj.min() if len(gj) else 0))
        self.order = np.argsort(self.key, kind="stable")
        self.sorted = self.key[self.order]

    def neighbour(self, di: int, dj: int, dz_max: float) -> np.ndarray:
        """Index of the sample one step (di, dj) away with the closest height within dz_max (−1: none)."""
        n = len(self.z)
        want = self.key + di * self.span + dj
        lo = np.searchsorted(self.sorted, want, "left")
        hi = np.searchsorted(self.sorted, want, "right")
        best, best_dz = np.full(n, -1), np.full(n, np.inf)
        for m in range(int((hi - lo).max()) if n else 0):
            ok = lo + m < hi
            j = self.order[np.minimum(lo + m, n - 1)]
            dz = np.abs(self.z[j] - self.z)
            ok &= (dz <= dz_max) & (dz < best_dz)
            best[ok], best_dz[ok] = j[ok], dz[ok]
        return best


def _inside(mesh: trimesh.Trimesh, pts: np.ndarray) -> np.ndarray:
    """Points inside the mesh: a ray straight up first leaves through an upward-facing facet."""
    if not len(pts):
        return np.zeros(0, dtype=bool)
    tri = mesh.ray.intersects_first(pts, np.tile([0.0, 0.0, 1.0], (len(pts), 1)))
    return (tri >= 0) & (mesh.face_normals[np.maximum(tri, 0), 2] > 0)


@dataclass
class _Body:
    """One body's downward samples: grid cells, heights, region, reach from support, and if bridged."""

    gi: np.ndarray
    gj: np.ndarray
    z: np.ndarray
    region: np.ndarray
    reach: np.ndarray
    bridged: np.ndarray


def _regions(grid: _Grid, cell: float):
    """Connected regions of samples (4-neighbour steps, heights within a cell), and the step graph
    with diagonal steps added inside each region (octile distances: within 8 % of straight lines)."""
    n = len(grid.z)

    def steps(offsets, dz_max):
        out = []
        for di, dj in offsets:
            nb = grid.neighbour(di, dj, dz_max)
            ok = np.nonzero(nb >= 0)[0]
            out.append((ok, nb[ok]))
        return out

    straight = steps(_STEPS4, cell + 1e-3)
    r = np.concatenate([a for a, _ in straight])
    c = np.concatenate([b for _, b in straight])
    _, labels = connected_components(coo_matrix((np.ones(len(r)), (r, c)), shape=(n, n)), directed=False)
    diag = [
        (a[labels[a] == labels[b]], b[labels[a] == labels[b]])
        for a, b in steps(((1, 1), (1, -1)), cell * math.sqrt(2) + 1e-3)
    ]
    rows = np.concatenate([r] + [a for a, _ in diag])
    cols = np.concatenate([c] + [b for _, b in diag])
    w = np.concatenate([np.full(len(r), cell)] + [np.full(len(a), cell * math.sqrt(2)) for a, _ in diag])
    return labels, coo_matrix((w, (rows, cols)), shape=(n, n))


def _anchors(mesh: trimesh.Trimesh, grid: _Grid, region: np.ndarray, cell: float, depth: float):
    """Which samples touch an anchor (their body's material ``depth`` below a neighbouring cell outside
    the region), which lie on their region's border, and each region's anchor cells."""
    pts_of, owner_of, cells_of = [], [], []  # per step of the 8: the samples, their owners, their cells
    for di, dj in _STEPS8:
        nb = grid.neighbour(di, dj, cell * math.sqrt(2) + 1e-3)
        border = np.nonzero((nb < 0) | (region[np.maximum(nb, 0)] != region))[0]
        ci, cj = grid.gi[border] + di, grid.gj[border] + dj
        pts_of.append(np.stack([(ci + 0.5) * cell, (cj + 0.5) * cell, grid.z[border] - depth], axis=1))
        owner_of.append(border)
        cells_of.append(np.stack([ci, cj], axis=1))
    pts, owner, cells = np.concatenate(pts_of), np.concatenate(owner_of), np.concatenate(cells_of)
    inside = _inside(mesh, pts)
    anchored = np.zeros(len(grid.z), dtype=bool)
    anchored[owner[inside]] = True
    border = np.zeros(len(grid.z), dtype=bool)
    border[owner] = True
    by_region: dict[int, set] = {}
    for r, (ci, cj) in zip(region[owner[inside]], cells[inside]):
        by_region.setdefault(int(r), set()).add((int(ci), int(cj)))
    return anchored, border, by_region


def _chords(ci: np.ndarray, cj: np.ndarray, anchor_keys: np.ndarray, span: int, angle: float):
    """Each cell's run across its region along ``angle`` (length in cells) and if both ends land on an anchor.

    Cells are binned into lines one cell wide along the direction; a run is a stretch of a line without
    a hole (steps ≤ 1.5 cells); its ends are looked up one to two cells beyond its first and last cell.
    """
    ca, sa = math.cos(angle), math.sin(angle)
    t = ci * ca + cj * sa
    line = np.rint(cj * ca - ci * sa).astype(np.int64)
    order = np.lexsort((t, line))
    ts, ls = t[order], line[order]
    new = np.ones(len(ts), dtype=bool)
    new[1:] = (ls[1:] != ls[:-1]) | (ts[1:] - ts[:-1] > 1.5)
    run = np.cumsum(new) - 1
    first = np.nonzero(new)[0]
    last = np.r_[first[1:], len(ts)] - 1

    def ends_on_anchor(idx: np.ndarray, sign: float) -> np.ndarray:
        hit = np.zeros(len(idx), dtype=bool)
        for step in (1.0, 1.5, 2.0):
            pi = np.rint(ci[order[idx]] + sign * step * ca).astype(np.int64)
            pj = np.rint(cj[order[idx]] + sign * step * sa).astype(np.int64)
            hit |= np.isin(pi * span + pj, anchor_keys)
        return hit

    both = ends_on_anchor(first, -1.0) & ends_on_anchor(last, 1.0)
    length, ok = np.empty(len(ts)), np.empty(len(ts), dtype=bool)
    length[order] = (ts[last] - ts[first] + 1.0)[run]
    ok[order] = both[run]
    return length, ok


def _bridged_region(gi: np.ndarray, gj: np.ndarray, anchor_cells: set, cell: float, test: np.ndarray) -> np.ndarray:
    """Samples of one region (those flagged ``test``) on a chord ≤ MAX_BRIDGE_MM anchored at both ends,
    in the direction of BRIDGE_DIRECTIONS that anchors most of them."""
    best = np.zeros(len(gi), dtype=bool)
    if not anchor_cells or not test.any():
        return best
    ac = np.array(sorted(anchor_cells), dtype=np.int64)
    i0, j0 = min(gi.min(), ac[:, 0].min()) - 4, min(gj.min(), ac[:, 1].min()) - 4
    span = int(max(gj.max(), ac[:, 1].max()) - j0 + 8)
    anchor_keys = np.unique((ac[:, 0] - i0) * span + (ac[:, 1] - j0))
    ci, cj = (gi - i0).astype(float), (gj - j0).astype(float)
    for m in range(BRIDGE_DIRECTIONS):
        length, ok = _chords(ci, cj, anchor_keys, span, math.pi * m / BRIDGE_DIRECTIONS)
        ok &= test & (length * cell <= MAX_BRIDGE_MM + 1e-9)
        if ok.sum() > best.sum():
            best = ok
    return best


def _analyse_body(mesh: trimesh.Trimesh, cell: float, depth: float, lip: float) -> tuple[_Body, float]:
    """Sample a body's downward surfaces off the bed; regions, anchors, bridges and reach. Also its bed area."""
    nz = mesh.face_normals[:, 2]
    down = nz < -math.cos(OVERHANG_ANGLE) - 1e-4
    on_bed = down & (mesh.triangles[:, :, 2].max(axis=1) <= BED_TOL_MM)
    bed_area = float(np.sum(mesh.area_faces[on_bed] * -nz[on_bed]))
    gi, gj, z = _raster(mesh.triangles[down & ~on_bed], cell)
    grid = _Grid(gi, gj, z)
    if not len(z):
        empty = np.zeros(0)
        return _Body(gi, gj, z, empty.astype(int), empty, empty.astype(bool)), bed_area
    region, graph = _regions(grid, cell)
    anchored, border, anchor_cells = _anchors(mesh, grid, region, cell, depth)
    n = len(z)
    # reach: distance along the region from the nearest anchor; a region with no anchor at all starts
    # from its whole extent at its border, so that its deepest point is its worst
    held = np.zeros(region.max() + 1, dtype=bool)
    held[region[anchored]] = True
    lo_i = np.full(len(held), np.inf)
    hi_i, lo_j, hi_j = -lo_i.copy(), lo_i.copy(), -lo_i.copy()
    np.minimum.at(lo_i, region, gi)
    np.maximum.at(hi_i, region, gi)
    np.minimum.at(lo_j, region, gj)
    np.maximum.at(hi_j, region, gj)
    extent = np.hypot(hi_i - lo_i + 1, hi_j - lo_j + 1) * cell
    src = np.nonzero(anchored | (border & ~held[region]))[0]
    start = np.where(anchored[src], cell / 2, extent[region[src]])
    g = coo_matrix(
        (
            np.concatenate([graph.data, graph.data, start]),
            (np.concatenate([graph.row, graph.col, np.full(len(src), n)]), np.concatenate([graph.col, graph.row, src])),
        ),
        shape=(n + 1, n + 1),
    ).tocsr()
    reach = dijkstra(g, directed=True, indices=n)[:n]
    bridged = np.zeros(n, dtype=bool)
    # a sample on an anchored chord ≤ MAX_BRIDGE_MM lies within half of it from an anchor (octile metric: +8 %)
    test = held[region] & (reach > lip) & (reach <= 0.55 * MAX_BRIDGE_MM + cell)
    order = np.argsort(region, kind="stable")
    bounds = np.searchsorted(region[order], np.arange(region.max() + 2))
    for r in np.nonzero(held)[0]:
        idx = order[bounds[r] : bounds[r + 1]]
        bridged[idx] = _bridged_region(gi[idx], gj[idx], anchor_cells.get(r, set()), cell, test[idx])
    return _Body(gi, gj, z, region, reach, bridged), bed_area


def _lowest_points(mesh: trimesh.Trimesh) -> np.ndarray:
    """Tips and knife edges in mid-air: vertices above the bed with no neighbour lower, some higher, a
    downward vertex normal (material above), and no downward facet (those are sampled)."""
    v = mesh.vertices
    e = mesh.edges_unique
    low, high = np.full(len(v), np.inf), np.full(len(v), -np.inf)
    for a, b in ((0, 1), (1, 0)):
        np.minimum.at(low, e[:, a], v[e[:, b], 2])
        np.maximum.at(high, e[:, a], v[e[:, b], 2])
    down = mesh.face_normals[:, 2] < -math.cos(OVERHANG_ANGLE) - 1e-4
    on_down = np.zeros(len(v), dtype=bool)
    on_down[mesh.faces[down].ravel()] = True
    tip = (low >= v[:, 2] - 1e-9) & (high > v[:, 2] + 1e-6) & (mesh.vertex_normals[:, 2] < -1e-3)
    return v[tip & (v[:, 2] > BED_TOL_MM) & ~on_down]


def _below(scene: trimesh.Trimesh, face_body: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each point: distance straight down to the first body (inf: none) and that body's index (−1)."""
    dist, body = np.full(len(pts), np.inf), np.full(len(pts), -1)
    if not len(pts):
        return dist, body
    origins = pts - [0.0, 0.0, 1e-4]
    locs, ray, tri = scene.ray.intersects_location(
        origins, np.tile([0.0, 0.0, -1.0], (len(pts), 1)), multiple_hits=False
    )
    dist[ray] = origins[ray, 2] - locs[:, 2] + 1e-4
    body[ray] = face_body[tri]
    return dist, body


@dataclass
class _Failure:
    body: str
    category: str
    reach: float
    where: np.ndarray
    under: str


def _classify(k, name, b: _Body, scene, face_body, names, cell, lip) -> tuple[dict, list[_Failure]]:
    """Areas per category for body k, and its failing places (one per failing region, its farthest sample)."""
    pts = np.stack([(b.gi + 0.5) * cell, (b.gj + 0.5) * cell, b.z], axis=1)
    dist, hit = _below(scene, face_body, pts)
    other = (hit >= 0) & (hit != k) & (dist < OPEN_BELOW_MM)
    held = ~other & (b.bridged | (b.reach <= lip))
    cat = np.where(other, 2, np.where(held, 1, 3))
    areas = {c: float(np.sum(cat == i) * cell * cell) for i, c in enumerate(CATEGORIES) if i}
    fails = []
    bad = np.nonzero(cat >= 2)[0]
    for r in np.unique(b.region[bad]):
        idx = bad[b.region[bad] == r]
        w = idx[np.argmax(b.reach[idx])]
        under = (
            (f"nothing: the bed is {b.z[w]:.2f} mm below")
            if hit[w] < 0
            else (f"{'its own body' if hit[w] == k else names[hit[w]]} {dist[w]:.2f} mm below")
        )
        fails.append(_Failure(name, CATEGORIES[cat[w]], float(b.reach[w]), pts[w], under))
    return areas, fails


def check_overhang(bodies, names, printer: Printer) -> CheckResult:
    """Downward-facing area per body by what holds it (bed, anchored, other body, air); fails on other body or air."""
    cell, depth, lip = grid_cell(printer), printer.layer_height_mm / 2, printer.nozzle_mm / 2
    scene = trimesh.util.concatenate(list(bodies))
    face_body = np.repeat(np.arange(len(bodies)), [len(b.faces) for b in bodies])
    table, fails = [], []
    for k, (mesh, name) in enumerate(zip(bodies, names)):
        b, bed = _analyse_body(mesh, cell, depth, lip)
        areas, body_fails = _classify(k, name, b, scene, face_body, names, cell, lip)
        areas["bed"] = bed
        for p in _lowest_points(mesh):
            body_fails.append(_Failure(name, "air", 0.0, p, "a lowest point with nothing of its body below"))
        table.append((name, areas))
        fails += body_fails
    summary = "; ".join(f"{n}: " + ", ".join(f"{c} {a[c]:.0f}" for c in CATEGORIES) for n, a in table)
    rules = (
        f"downward = flatter than {math.degrees(OVERHANG_ANGLE):g}° from horizontal; bridges ≤ {MAX_BRIDGE_MM:g} mm "
        f"anchored at both ends on the same body, lips ≤ {lip:g} mm; ≥ {OPEN_BELOW_MM:g} mm open above another "
        f"body; grid {cell:g} mm"
    )
    bad_area = sum(a["other body"] + a["air"] for _, a in table)
    if not fails:
        return CheckResult("overhang", True, 0.0, 0.0, None, f"areas [mm²] {summary}; {rules}")
    w = max(fails, key=lambda f: f.reach)
    text = (
        f"worst: {w.body}, {w.category}, {w.reach:.1f} mm from its body's nearest support; under it: "
        f"{w.under}; {len(fails)} failing places; areas [mm²] {summary}; {rules}"
    )
    if printer.soluble_support:
        return CheckResult(
            "overhang",
            None,
            round(bad_area, 1),
            0.0,
            point(w.where),
            f"skipped: {printer.key} prints soluble support under these; without it: {text}",
        )
    return CheckResult("overhang", False, round(bad_area, 1), 0.0, point(w.where), text)
