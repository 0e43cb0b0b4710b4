"""rjcad.check.gcode on hand-written G-code: every number below is worked out by hand from the text."""

import math

import numpy as np
import pytest

from rjcad.check.gcode import ARC_CHORD_MM, parse_gcode

ROAD = 0.45 * 0.2 - 0.2 * 0.2 * (1 - math.pi / 4)  # rounded-rectangle road, w 0.45, h 0.2 [mm²]
FIL = math.pi * 1.75**2 / 4  # filament cross-section [mm²]


def test_absolute_e_travel_and_retraction_split_paths():
    g = """
G90
M82
G92 E0
;LAYER_CHANGE
;Z:0.2
;HEIGHT:0.2
G1 Z0.2 F3000
G1 X10 Y10 F9000 ; travel
;TYPE:External perimeter
;WIDTH:0.45
G1 X20 Y10 E1.0
G1 X20 Y15 E1.5
G1 E0.7 F2100 ; retract
G1 X30 Y30 F9000 ; travel
G1 E1.5 ; unretract
;TYPE:Solid infill
;WIDTH:0.5
G1 X31 Y30 E1.6
"""
    tp = parse_gcode(g)
    assert len(tp.x0) == 3
    assert (tp.x0[0], tp.y0[0], tp.x1[0], tp.y1[0]) == (10, 10, 20, 10)
    assert (tp.x0[1], tp.y0[1], tp.x1[1], tp.y1[1]) == (20, 10, 20, 15)
    assert tp.length.tolist() == pytest.approx([10, 5, 1])
    assert tp.path[0] == tp.path[1] != tp.path[2]  # the travel after the retraction ends the path
    assert tp.width.tolist() == pytest.approx([0.45, 0.45, 0.5])
    assert [tp.kinds[k] for k in tp.kind] == ["External perimeter"] * 2 + ["Solid infill"]
    assert tp.z.tolist() == [0.2] * 3 and tp.height.tolist() == [0.2] * 3
    assert tp.obj.tolist() == [-1] * 3


def test_relative_e_g92_and_wipe_is_not_an_extrusion():
    g = """
G90
M83
G1 Z0.4
G1 X0 Y0
G1 X5 Y0 E0.3
G1 X6 Y0 E-0.8 ; wipe while retracting: moves, pulls filament
G92 E0
G1 X6 Y2 E0.2
"""
    tp = parse_gcode(g)
    assert len(tp.x0) == 2
    assert (tp.x0[1], tp.y0[1], tp.x1[1], tp.y1[1]) == (6, 0, 6, 2)
    assert tp.path[0] != tp.path[1]  # the wipe broke the path
    # no ;HEIGHT: the layer height is the z of the only layer above the bed
    assert tp.height.tolist() == pytest.approx([0.4, 0.4])


def test_width_from_the_filament_pushed_when_no_width_comment():
    e = ROAD * 10 / FIL  # filament for a 10 mm road 0.45 × 0.2
    g = f"""
G90
M82
; filament_diameter = 1.75
G1 Z0.2
G1 X0 Y0
G1 X10 Y0 E{e:.6f}
;HEIGHT:0.2
G1 Z0.4
G1 X10 Y10 E{2 * e:.6f}
"""
    tp = parse_gcode(g)
    assert tp.width.tolist() == pytest.approx([0.45, 0.45], abs=1e-4)
    assert tp.layers().tolist() == [0.2, 0.4]


def test_filament_diameter_from_the_config_block_changes_the_width():
    e = ROAD * 10 / (math.pi * 2.85**2 / 4)
    tp = parse_gcode(f"G90\nM82\nG1 Z0.2\nG1 X0 Y0\nG1 X10 Y0 E{e:.6f}\n; filament_diameter = 2.85\n")
    assert tp.width[0] == pytest.approx(0.45, abs=1e-4)


def test_object_labels_from_comments_and_from_m486():
    g = """
G90
M83
G1 Z0.2
; printing object ground.stl id:0 copy 0
G1 X0 Y0
G1 X1 Y0 E0.1
; stop printing object ground.stl id:0 copy 0
; printing object moving part id:1 copy 0
G1 X2 Y0 E0.1
; stop printing object moving part id:1 copy 0
M486 S3 A"cheek"
M486 S3
G1 X3 Y0 E0.1
M486 S-1
G1 X4 Y0 E0.1
; printing object ground.stl id:0 copy 0
G1 X5 Y0 E0.1
"""
    tp = parse_gcode(g)
    assert tp.objects == ["ground.stl", "moving part", "cheek"]
    assert tp.obj.tolist() == [0, 1, 2, -1, 0]
    assert len(set(tp.path.tolist())) == 5  # a change of object ends a path


def test_arc_is_split_into_short_chords_on_the_circle():
    g = """
G90
M83
G1 Z0.2
G1 X5 Y0
G3 X0 Y5 I-5 J0 E1.0
G2 X5 Y0 I0 J-5 E1.0
"""
    tp = parse_gcode(g)
    n = len(tp.x0)
    assert n >= 2 * math.ceil(5 * math.pi / 2 / ARC_CHORD_MM) - 2
    assert tp.length.max() <= ARC_CHORD_MM + 1e-9
    r = np.hypot(np.r_[tp.x0, tp.x1], np.r_[tp.y0, tp.y1])
    assert r == pytest.approx(np.full(len(r), 5.0), abs=1e-9)
    assert (tp.x1[n // 2 - 1], tp.y1[n // 2 - 1]) == pytest.approx((0, 5))
    assert (tp.x1[-1], tp.y1[-1]) == pytest.approx((5, 0))
    # G3 turns counter-clockwise through the first quadrant, G2 comes back clockwise the same way
    # (the wrong sense would go the long way round, through the other three quadrants)
    assert np.all(np.r_[tp.x1, tp.y1] >= -1e-9)
    assert tp.length.sum() == pytest.approx(2 * (5 * math.pi / 2), rel=1e-3)


def test_relative_positioning_and_z_hop_between_layers():
    g = """
G91
G1 Z0.2
G1 X1 Y1 E0.05
G1 X1 E0.05
G1 Z0.4 ; hop
G1 X5
G1 Z-0.4
G1 X1 E0.05
G1 Z0.2
G1 X-1 E0.05
"""
    tp = parse_gcode(g)
    assert tp.x1.tolist() == [1, 2, 8, 7] and tp.y1.tolist() == [1, 1, 1, 1]
    assert tp.z.tolist() == pytest.approx([0.2, 0.2, 0.2, 0.4])
    assert len(set(tp.path.tolist())) == 3
    assert tp.layers().tolist() == pytest.approx([0.2, 0.4])


def test_comments_words_and_lowercase_are_read():
    g = "G90\nM83\ng1 z0.2\nG1 X0 Y0 ; go\nG1 x3 y4 e0.2 ; a road\nG1 X3 Y4 E0.2 ; no XY move: prime, not a road\n"
    tp = parse_gcode(g)
    assert len(tp.x0) == 1 and tp.length[0] == pytest.approx(5.0)


def test_malformed_width_falls_back_to_the_filament_pushed():
    e = ROAD * 10 / FIL
    tp = parse_gcode(f"G90\nM82\n;HEIGHT:0.2\n;WIDTH:wide\nG1 Z0.2\nG1 X0 Y0\nG1 X10 Y0 E{e:.6f}\n")
    assert tp.width[0] == pytest.approx(0.45, abs=1e-4)


def test_empty_or_travel_only_gcode_has_no_rows():
    tp = parse_gcode("G90\nG1 X1 Y1\nG1 X2 Y2 F100\n")
    assert len(tp.x0) == 0 and tp.objects == [] and len(tp.layers()) == 0


# ---------------------------------------------------------------- the numpy reader against the line-by-line one
# (and on the default joint's G-code: tests/test_check_print.py)

MIXED = """; filament_diameter = 1.75
G90
M82
G92 E0
;TYPE:Perimeter
;WIDTH:0.45
;HEIGHT:0.2
G1 Z.2 F7800
; printing object body0.stl id:0 copy 0
G1 X10.5 Y-3 F9000
G1 X20.125 Y-3 E.5
g1 x21 y-2 e0.6 ; lowercase, with a comment
G1 X22 Y-2 E0.6
G1 X22 Y-2 E0.7
G1 X23 Y-1 Ebad E0.8
G1 X24 Y-1 E1e-0
G1 E.2 F2400
; stop printing object body0.stl id:0 copy 0
M486 S1 A"second part"
M486 S1
;TYPE:Solid infill
;WIDTH:wide
G1 X30 Y30
G1 E1.0
G1 X31 Y30 E1.1
G3 X32 Y31 I0 J1 E1.3
G1 Z.4
G91
G1 X1 E0.1
M83
G1 X1 Y1 E0.1
G92 X0 Y0
G90
G1 X2 Y0 E0.1
M486 S-1
G1 X3 Y0 E0.1
"""


@pytest.mark.parametrize("text", [MIXED, MIXED.replace("\n", "\r\n"), "", "G1 X1\n", "G1 X1 Y1 E1"])
def test_numpy_reader_gives_what_the_line_by_line_reader_gave(text):
    from gcode_reference import assert_same
    from gcode_reference import parse_gcode as reference

    assert_same(parse_gcode(text), reference(text))
    assert len(parse_gcode(MIXED).x0) > 8
