"""Reading a supports-off slice: does every road rest on the bed or on its own body's previous layer?

The analysis behind the slicer check, on ``rjcad.check.gcode.Toolpaths`` whose objects are the
bodies, layer by layer:

- every extrusion is sampled every SAMPLE_MM along its path;
- a sample is supported on the first layer (the bed), or when a road of the same body in the
  previous layer lies within h·tan 45° + (w_prev − w)/2 + TOL_MM of it: its centre line is over
  that road, or overhangs it by no more than the 45° rule allows (h the layer height, w widths), or it
  lies over a small void: roads of the previous layer within w + h on every side of it (a teardrop's
  tip, a sliver that solid infill left in a corner), which it spans;
- unsupported samples form runs along their path. A run is excused as a bridge when it is straight
  (within half a road of its chord, or ≤ SHORT_SPAN_MM long), ≤ MAX_BRIDGE_MM, anchored at both
  ends on supported samples of its path, and no other body lies within OPEN_BELOW_MM below it; or as
  a lip when it is no longer than LIP_ROADS road widths. Every other run fails: the filament is laid
  on nothing;
- in every layer, the closest approach of two bodies' roads: centre distance − half widths, the
  closest pair refined to the exact distance between their two moves.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from rjcad.check.gcode import Toolpaths
from rjcad.check.overhang import MAX_BRIDGE_MM, OPEN_BELOW_MM

#: Spacing of the samples along each road [mm] (a sample stands for 0.2 mm of road: the nearest
#: sample of a road then lies within √(d² + 0.1²) of a point at distance d; TOL_MM covers it).
SAMPLE_MM = 0.2
#: A run anchored at both ends and no longer than this is excused even if it turns: a small void
#: inside the section (where solid infill turns, say) spanned by the road's two anchors [mm].
SHORT_SPAN_MM = 2.0
#: A run no longer than this many road widths is excused: a road's end or corner overhanging by a width.
LIP_ROADS = 1.0
#: Slack on distances between roads: G-code rounding (1 µm) and roads' rounded ends [mm].
TOL_MM = 0.05


@dataclass
class Run:
    """A stretch of filament laid on nothing (or a bridge) in one layer of one body."""

    layer: int
    z: float
    body: str
    length: float
    anchors: int
    where: tuple[float, float, float]
    under: str


@dataclass
class Analysis:
    layers: int = 0
    failures: list[Run] = field(default_factory=list)
    bridges: int = 0
    longest_bridge: float = 0.0
    min_gap: float = math.inf
    gap_where: tuple[float, float, float] | None = None
    gap_pair: tuple[str, str] | None = None
    gap_layer: int = -1


@dataclass
class _Layer:
    """One body's samples in one layer, and a tree over them."""

    x: np.ndarray
    y: np.ndarray
    w: np.ndarray
    path: np.ndarray
    s: np.ndarray
    seg: np.ndarray

    def __post_init__(self):
        self.tree = cKDTree(np.stack([self.x, self.y], axis=1))
        self.w_max = float(self.w.max())
        self.lo = np.array([self.x.min(), self.y.min()])
        self.hi = np.array([self.x.max(), self.y.max()])

    def near(self, other: _Layer, reach: float) -> np.ndarray:
        """Indices of this layer's samples within ``reach`` of the other's bounding box (the only ones that can
        lie within ``reach`` of its samples)."""
        return np.flatnonzero(
            (self.x >= other.lo[0] - reach)
            & (self.x <= other.hi[0] + reach)
            & (self.y >= other.lo[1] - reach)
            & (self.y <= other.hi[1] + reach)
        )


def _sample(tp: Toolpaths, idx: np.ndarray) -> _Layer:
    """Samples every SAMPLE_MM along moves ``idx`` (file order), with their arc length along their path."""
    length = tp.length[idx]
    n = np.maximum(1, np.ceil(length / SAMPLE_MM)).astype(np.int64)
    rep = np.repeat(np.arange(len(idx)), n)
    t = (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n) + 0.5) / n[rep]
    path = tp.path[idx]
    cum = np.cumsum(length) - length
    start = np.r_[True, path[1:] != path[:-1]]
    base = np.maximum.accumulate(np.where(start, cum, -np.inf))
    seg = idx[rep]
    return _Layer(
        tp.x0[seg] + t * (tp.x1[seg] - tp.x0[seg]),
        tp.y0[seg] + t * (tp.y1[seg] - tp.y0[seg]),
        tp.width[seg],
        path[rep],
        (cum - base)[rep] + t * length[rep],
        seg,
    )


def _supported(cur: _Layer, prev: _Layer | None, h: float, enclosed: bool = True) -> np.ndarray:
    """Samples within h·tan 45° + (w_prev − w)/2 + TOL_MM of a road of the previous layer, or (``enclosed``)
    over a small void: roads of the previous layer within w + h + TOL_MM of the sample on every side (no
    angular gap of 180° or more among them), so that the road spans at most about two road widths."""
    if prev is None:
        return np.zeros(len(cur.x), dtype=bool)
    pts = np.stack([cur.x, cur.y], axis=1)
    d, i = prev.tree.query(pts, distance_upper_bound=h + prev.w_max / 2 + TOL_MM)
    found = np.isfinite(d)
    allow = h + (prev.w[np.minimum(i, len(prev.w) - 1)] - cur.w) / 2 + TOL_MM
    ok = found & (d <= allow)
    if not enclosed or ok.all():
        return ok
    bad = np.flatnonzero(~ok)
    prev_pts = np.stack([prev.x, prev.y], axis=1)
    for b, near in zip(bad, prev.tree.query_ball_point(pts[bad], cur.w[bad] + h + TOL_MM)):
        if len(near) < 3:
            continue
        v = prev_pts[near] - pts[b]
        ang = np.sort(np.arctan2(v[:, 1], v[:, 0]))
        gaps = np.diff(np.r_[ang, ang[0] + 2 * math.pi])
        ok[b] = gaps.max() < math.pi
    return ok


def _below(pts: np.ndarray, w: float, z: float, h: float, history, me: int) -> tuple[int, float]:
    """What lies under the points within OPEN_BELOW_MM of open space: the nearest other body's roads if
    any (a road of it overlaps them in plan), else the nearest of this body's; (body, open space) or (−1, inf)."""
    own = None
    for lz, layer in reversed(history):
        gap = z - h - lz
        if gap > OPEN_BELOW_MM + 1e-6:
            break
        for o, lay in layer.items():
            if (o == me and own is not None) or not len(pts):
                continue
            if np.isfinite(lay.tree.query(pts, distance_upper_bound=w / 2 + lay.w_max / 2)[0]).any():
                if o != me:
                    return o, max(gap, 0.0)
                own = (o, max(gap, 0.0))
    return own if own is not None else (-1, math.inf)


def _runs(cur: _Layer, ok: np.ndarray):
    """Maximal runs of unsupported samples along each path: (first, last, anchors before/after)."""
    bad = ~ok
    newpath = np.r_[True, cur.path[1:] != cur.path[:-1]]
    starts = np.nonzero(bad & (newpath | np.r_[True, ~bad[:-1]]))[0]
    endpath = np.r_[cur.path[1:] != cur.path[:-1], True]
    ends = np.nonzero(bad & (endpath | np.r_[~bad[1:], True]))[0]
    before = (starts > 0) & ~newpath[starts]
    after = (ends < len(ok) - 1) & ~endpath[ends]
    return starts, ends, before, after


def _judge_runs(a: Analysis, cur: _Layer, ok, k, z, h, history, names, lz) -> None:
    """Excuse bridges and lips; record every other unsupported run as a failure."""
    for s0, s1, bef, aft in zip(*_runs(cur, ok)):
        length = float(cur.s[s1] - cur.s[s0] + SAMPLE_MM)
        w = float(cur.w[s0 : s1 + 1].max())
        if length <= LIP_ROADS * w:
            continue
        lo, hi = (s0 - 1 if bef else s0), (s1 + 1 if aft else s1)
        pts = np.stack([cur.x[lo : hi + 1], cur.y[lo : hi + 1]], axis=1)
        chord = pts[-1] - pts[0]
        rel = pts - pts[0]
        dev = np.abs(chord[0] * rel[:, 1] - chord[1] * rel[:, 0]) / max(float(np.hypot(*chord)), 1e-9)
        straight = dev.max() <= w / 2 or length <= SHORT_SPAN_MM
        if bef and aft and length <= MAX_BRIDGE_MM and straight:
            other, _ = _below(pts[1:-1], w, z, h, history, k)
            if other < 0 or other == k:
                a.bridges += 1
                a.longest_bridge = max(a.longest_bridge, length)
                continue
        far = (s0 + s1) // 2 if (bef and aft) else (s1 if bef else s0)
        under_body, open_gap = _below(np.array([[cur.x[far], cur.y[far]]]), w, z, h, history, k)
        under = (
            f"{'its own body' if under_body == k else names[under_body]} {open_gap:.2f} mm below"
            if under_body >= 0
            else f"nothing within {OPEN_BELOW_MM:g} mm below"
        )
        a.failures.append(
            Run(
                lz,
                z,
                names[k],
                length,
                int(bef) + int(aft),
                (float(cur.x[far]), float(cur.y[far]), round(z - h / 2, 3)),
                under,
            )
        )


def _seg_distance(tp: Toolpaths, i: int, j: int) -> float:
    """Exact distance between moves i and j in XY."""
    p = np.array([[tp.x0[i], tp.y0[i]], [tp.x1[i], tp.y1[i]]])
    q = np.array([[tp.x0[j], tp.y0[j]], [tp.x1[j], tp.y1[j]]])

    def point_seg(c, a, b):
        ab = b - a
        t = 0.0 if not ab.any() else float(np.clip(np.dot(c - a, ab) / np.dot(ab, ab), 0, 1))
        return float(np.hypot(*(a + t * ab - c)))

    return min(point_seg(p[0], *q), point_seg(p[1], *q), point_seg(q[0], *p), point_seg(q[1], *p))


def _gaps(a: Analysis, tp: Toolpaths, cur: dict, z: float, h: float, lz: int, names, min_gap: float) -> None:
    """Closest approach of every two bodies' roads in this layer."""
    objs = sorted(cur)
    for m, oa in enumerate(objs):
        for ob in objs[m + 1 :]:
            la, lb = cur[oa], cur[ob]
            reach = la.w_max / 2 + lb.w_max / 2 + min_gap + 0.5
            near = la.near(lb, reach)
            if not len(near):
                continue
            d, i = lb.tree.query(np.stack([la.x[near], la.y[near]], axis=1), distance_upper_bound=reach)
            hit = np.isfinite(d)
            if not hit.any():
                continue
            gap = np.where(hit, d - la.w[near] / 2 - lb.w[np.minimum(i, len(lb.w) - 1)] / 2, np.inf)
            best = int(np.argmin(gap))
            k, j = int(near[best]), int(i[best])
            exact = _seg_distance(tp, int(la.seg[k]), int(lb.seg[j])) - la.w[k] / 2 - lb.w[j] / 2
            if exact < a.min_gap:
                a.min_gap = float(exact)
                a.gap_where = (float((la.x[k] + lb.x[j]) / 2), float((la.y[k] + lb.y[j]) / 2), round(z - h / 2, 3))
                a.gap_pair, a.gap_layer = (names[oa], names[ob]), lz


def analyse(tp: Toolpaths, names: list[str], min_gap: float) -> Analysis:
    """Layer by layer: unsupported runs per body (see the module docstring) and the closest two bodies come."""
    z_layers = tp.layers()
    lay = np.searchsorted(z_layers, np.round(tp.z, 4))
    order = np.lexsort((np.arange(len(lay)), lay))
    bounds = np.searchsorted(lay[order], np.arange(len(z_layers) + 1))
    a = Analysis(layers=len(z_layers))
    history: deque = deque(maxlen=math.ceil(OPEN_BELOW_MM / 0.05) + 2)
    for L, z in enumerate(z_layers):
        idx = order[bounds[L] : bounds[L + 1]]
        idx = idx[tp.obj[idx] >= 0]
        h = float(np.median(tp.height[idx])) if len(idx) else 0.0
        cur = {int(o): _sample(tp, idx[tp.obj[idx] == o]) for o in np.unique(tp.obj[idx])}
        prev = history[-1][1] if history and abs(history[-1][0] - (z - h)) < 1e-3 else {}
        for k, c in cur.items():
            ok = np.ones(len(c.x), dtype=bool) if L == 0 else _supported(c, prev.get(k), h)
            if not ok.all():
                _judge_runs(a, c, ok, k, float(z), h, history, names, L + 1)
        _gaps(a, tp, cur, float(z), h, L + 1, names, min_gap)
        history.append((float(z), cur))
    return a
