"""The bearing model's tilt of the desktop hub, checked on the built solids (issue #36).

The model (rjcad.physics.bearing) is linearised and uses contact points on the designed surfaces. Here the
default joint's bodies, as built, follow the model's motion under the largest tendon moment (θ_j = 0) as an
exact rigid motion, scaled from 0, until the meshes first touch (manifold3d's distance between the bodies).
The spring is cut off the moving body (z above its strips): it winds, it does not move rigidly with the hub.
docs/bearing.md quotes what this finds.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from rjcad.design.layout_desktop import ROOF_LAND

DOC = Path(__file__).resolve().parents[1] / "docs" / "bearing.md"


@pytest.fixture(scope="module")
def first_touch():
    from scipy.spatial.transform import Rotation

    from rjcad.cad.build import build
    from rjcad.check.mesh_checks import to_manifold
    from rjcad.design.params import JointParams
    from rjcad.physics import bearing as B

    p = JointParams()
    built = build(p)
    ground = to_manifold(built.meshes["ground"])
    hub = to_manifold(built.meshes["moving"]).trim_by_plane((0.0, 0.0, 1.0), p.desktop.b + 0.3)
    state = B.driven(p, 0.4, 0.0, 1, "tendon").state
    u, phi = state.displacement[:3], np.array([*state.displacement[3:5], 0.0])

    def moved(s: float):
        R = Rotation.from_rotvec(s * phi).as_matrix()  # about the joint axis (the origin), then u
        return hub.transform(np.hstack([R, (s * u)[:, None]]).tolist())

    lo, hi = 0.0, 1.0
    assert moved(hi).min_gap(ground, 1.0) == 0.0  # the model's whole motion does not fit the solids
    for _ in range(16):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if moved(mid).min_gap(ground, 1.0) > 1e-3 else (lo, mid)
    overlap = moved(hi + 0.02) ^ ground
    lo_box, hi_box = np.array(overlap.bounding_box()).reshape(2, 3)
    where = 0.5 * (lo_box + hi_box)
    contacts = B.contacts_of(p)
    wall = next(c for c in contacts if c.surface == "spring on cup wall").gap
    # the model's own contacts along the same motion, with exact (not linearised) gaps: no CAD, no mesh
    m_lo, m_hi = 0.0, 1.0
    for _ in range(30):
        mid = 0.5 * (m_lo + m_hi)
        m_lo, m_hi = (mid, m_hi) if B.exact_gaps(contacts, mid * state.displacement).min() > 1e-3 else (m_lo, mid)
    gaps = B.exact_gaps(contacts, m_hi * state.displacement)
    return {
        "model_tilt": math.degrees(m_lo * float(np.linalg.norm(phi))),
        "model_first": contacts[int(np.argmin(gaps))],
        "p": p,
        "linear_tilt": math.degrees(state.tilt),
        "tilt": math.degrees(lo * float(np.linalg.norm(phi))),
        "where": where,
        "spring_gap": (1.0 - lo) * wall,
    }


def test_the_built_hub_rocks_until_its_collar_meets_the_top_of_the_bore(first_touch):
    t, L = first_touch, first_touch["p"].desktop
    assert t["linear_tilt"] == pytest.approx(9.57, abs=0.05)  # the model's own answer (docs/bearing.md)
    assert 6.5 < t["tilt"] < 8.0  # the rocking is real: 7°, not 9.6°, on the exact motion
    x, y, z = t["where"]
    assert x < 0 and abs(math.hypot(x, y) - L.R_bore) < 0.6  # the collar, on the side the tendon pulls to
    assert abs(z - L.roof_top(L.R_bore + ROOF_LAND)) < 0.3  # at the top of the bore
    assert t["spring_gap"] > 0.5  # the spring has not reached the cup wall by then


def test_the_models_exact_gaps_find_the_solids_first_touch(first_touch):
    """Along the same motion, the model's contacts with exact gaps (rjcad.physics.bearing.exact_gaps) close first
    where and when the solids touch: the collar on the bore's top rim, within 0.2° of tilt. So the model's
    geometry is the built one, and its linearised 9.6° (all gaps closed at once) is the linearisation's error."""
    t, L = first_touch, first_touch["p"].desktop
    c = t["model_first"]
    assert c.surface == "collar" and c.point[0] < 0
    assert c.point[2] == pytest.approx(L.roof_top(L.R_bore + ROOF_LAND))
    assert t["model_tilt"] == pytest.approx(t["tilt"], abs=0.2)


def test_the_page_quotes_the_check_on_the_solids(first_touch):
    text = DOC.read_text(encoding="utf-8")
    quoted = dict(re.findall(r"`(mesh_\w+)=([-\d.]+)`", text))
    t = first_touch
    assert float(quoted["mesh_touch_tilt"]) == pytest.approx(t["tilt"], abs=0.05)
    assert float(quoted["mesh_touch_z"]) == pytest.approx(t["where"][2], abs=0.1)
    assert float(quoted["mesh_spring_wall_gap"]) == pytest.approx(t["spring_gap"], abs=0.02)
    assert float(dict(re.findall(r"`(model_\w+)=([-\d.]+)`", text))["model_touch_tilt"]) == pytest.approx(
        t["model_tilt"], abs=0.05
    )


def test_first_touch_is_this_check_on_the_model(first_touch):
    """rjcad.physics.bearing.first_touch (the manifest block's ``first_touch``) finds what this module's own
    bisection on the exact gaps finds, and so the solids' first touch."""
    from rjcad.physics import bearing as B

    t = first_touch
    touch = B.first_touch(B.driven(t["p"], 0.4, 0.0, 1, "tendon").state)
    assert touch is not None and touch.contact == t["model_first"]
    assert math.degrees(touch.tilt) == pytest.approx(t["model_tilt"], abs=0.01)
    assert math.degrees(touch.tilt) == pytest.approx(t["tilt"], abs=0.2)
