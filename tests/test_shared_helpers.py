"""The small shared modules: rjcad.DEG, rjcad.paper (the paper's values), rjcad.validate (the one
range check), rjcad.check.mesh_checks.to_manifold (float64) and rjcad.plotting (metadata-free, reproducible PNGs)."""

import math
import struct

import numpy as np
import pytest
import trimesh

from rjcad import DEG
from rjcad.check.mesh_checks import to_manifold
from rjcad.errors import ParameterError
from rjcad.paper import FINGER, JOINT
from rjcad.plotting import png_bytes, pyplot, save_png
from rjcad.validate import default_limit, in_range

# ---------------------------------------------------------------- units and the paper's values


def test_deg_is_one_degree_in_radians():
    assert 180 * DEG == math.pi and math.radians(37.5) == pytest.approx(37.5 * DEG, rel=1e-15)


def test_the_paper_table_holds_the_papers_numbers():
    assert (JOINT.stiffness, JOINT.mu_j, JOINT.gamma_pos, JOINT.gamma_neg, JOINT.beta_pos, JOINT.beta_neg) == (
        5.19,
        6.92,
        1.89,
        3.15,
        1.24,
        0.67,
    )
    assert JOINT.mu_j * JOINT.normal_load == pytest.approx(10.39, rel=0.002)  # 10.39 N·mm measured, μ_j rounded
    assert JOINT.preload == pytest.approx(70 * DEG) and JOINT.pulley_radius == 6.0
    assert FINGER.designed_stiffness == (5.2, 7.8, 10.4)  # K1, 1.5·K1, 2·K1
    assert FINGER.measured_end_deg == (65.0, 50.0, 50.0) and FINGER.stroke == 25.0 and FINGER.link_length == 40.0


def test_the_physics_and_the_finger_template_use_the_paper_table():
    from rjcad.io.templates import PAPER_FINGER
    from rjcad.physics.joint import PAPER_JOINT

    for name in ("stiffness", "preload", "mu_j", "gamma_pos", "gamma_neg", "beta_pos", "beta_neg", "pulley_radius"):
        assert getattr(PAPER_JOINT, name) == pytest.approx(getattr(JOINT, name), rel=1e-12), name
    assert tuple(j["stiffness_nmm_per_rad"] for j in PAPER_FINGER["joint"]) == FINGER.designed_stiffness
    assert PAPER_FINGER["defaults"]["link_length_mm"] == FINGER.link_length


# ---------------------------------------------------------------- the range check


@pytest.mark.parametrize(
    "kw, inside, outside",
    [
        ({"lo": 0.0, "hi": 1.0}, [0.0, 0.5, 1.0], [-1e-9, 1.000001]),
        ({"lo": 0.0, "hi": 1.0, "lo_open": True}, [1e-12, 1.0], [0.0, -1.0]),
        ({"lo": 0.0, "hi": 1.0, "hi_open": True}, [0.0, 0.999], [1.0]),
        ({"lo": 2.0}, [2.0, 1e300], [1.999]),
        ({"hi": 2.0, "hi_open": True}, [-1e300, 1.999], [2.0]),
        ({"lo": 0.0, "hi": 1.0, "tol": 0.01}, [-0.01, 1.01], [-0.011, 1.011]),
    ],
)
def test_in_range_closed_and_open_ends(kw, inside, outside):
    for v in inside:
        assert in_range("x", v, **kw) == v
    for v in outside:
        with pytest.raises(ParameterError):
            in_range("x", v, **kw)


def test_in_range_messages_name_the_parameter_and_the_range():
    with pytest.raises(ParameterError) as e:
        in_range("clearance", 0.05, 0.15, 0.6, unit="mm")
    assert str(e.value) == "clearance = 0.05 mm is invalid: must be in [0.15, 0.6] mm"
    assert e.value.parameter == "clearance" and e.value.limit == "must be in [0.15, 0.6] mm"
    with pytest.raises(ParameterError) as e:
        in_range("rotation", 120 * DEG, 15 * DEG, 110 * DEG, deg=True)
    assert str(e.value) == "rotation = 120 deg is invalid: must be in [15, 110]"
    with pytest.raises(ParameterError) as e:
        in_range("stiffness", -1.0, 0.0, lo_open=True, limit="must be > 0 (a spring)")
    assert e.value.limit == "must be > 0 (a spring)"
    assert default_limit(0, 1, lo_open=True, hi_open=True) == "must be in (0, 1)"
    assert default_limit(None, 5, "N") == "must be <= 5 N" and default_limit(None, None) == "must be a finite number"


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), "abc", None, True, [1.0]])
def test_in_range_rejects_what_is_not_a_finite_number(bad):
    with pytest.raises(ParameterError) as e:
        in_range("k", bad, 0.0, 10.0, not_a_number="must be a number")
    finite_nan = isinstance(bad, float)
    assert e.value.limit == ("must be in [0, 10]" if finite_nan else "must be a number")
    assert in_range("k", "2.5", 0, 10) == 2.5 and in_range("k", 3, 0, 10) == 3.0


# ---------------------------------------------------------------- mesh conversion


def test_to_manifold_keeps_volume_and_double_precision():
    box = trimesh.creation.box(extents=(10.0, 20.0, 30.0))
    man = to_manifold(box)
    assert man.status().name == "NoError" and man.volume() == pytest.approx(6000.0, rel=1e-12)
    far = box.copy()
    far.apply_translation((1e6, 0, 0))  # float32 would round 1e6 + 5 to a multiple of 0.0625
    far.vertices[:, 0] += 1e-4
    m = to_manifold(far)
    xs = np.asarray(m.to_mesh64().vert_properties)[:, 0]
    assert xs.min() == pytest.approx(1e6 - 5 + 1e-4, abs=1e-9)
    assert m.volume() == pytest.approx(6000.0, rel=1e-9)


def test_to_manifold_of_an_open_mesh_is_not_a_solid():
    box = trimesh.creation.box(extents=(1, 1, 1))
    box.update_faces(np.arange(len(box.faces)) > 0)  # one triangle missing
    assert to_manifold(box).status().name != "NoError"


# ---------------------------------------------------------------- plots


def figure():
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0, 1, 2], [0, 1, 4], label="y = x²")
    ax.legend()
    return fig


def png_chunks(data: bytes) -> list[tuple[bytes, bytes]]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    out, i = [], 8
    while i < len(data):
        (n,) = struct.unpack(">I", data[i : i + 4])
        out.append((data[i + 4 : i + 8], data[i + 8 : i + 8 + n]))
        i += 12 + n
    return out


def test_png_has_no_software_chunk_and_reruns_are_identical():
    import matplotlib

    assert matplotlib.get_backend().lower() == "agg"
    a, b = png_bytes(figure(), dpi=50), png_bytes(figure(), dpi=50)
    assert a == b
    chunks = png_chunks(a)
    assert chunks[0][0] == b"IHDR" and chunks[-1][0] == b"IEND"
    text = b"".join(d for kind, d in chunks if kind in (b"tEXt", b"iTXt", b"zTXt"))
    assert b"Software" not in text and b"matplotlib" not in text.lower()
    width, height = struct.unpack(">II", chunks[0][1][:8])
    assert (width, height) == (150, 100)


def test_png_bytes_closes_the_figure_and_save_png_writes_atomically(tmp_path):
    plt = pyplot()
    before = len(plt.get_fignums())
    data = png_bytes(figure())
    assert len(plt.get_fignums()) == before
    p = save_png(figure(), tmp_path / "plots" / "a.png")
    assert p.read_bytes() == data
    assert [q.name for q in p.parent.iterdir()] == ["a.png"] and len(plt.get_fignums()) == before
