"""rjcad.io.prusaslicer: PrusaSlicer's vendor printer profiles turned into rjcad printer profiles.

A synthetic bundle (written here) pins the rules with values worked out by hand; the bundles installed by
Debian's prusa-slicer package (2.5.0 here) are read for three vendors' printers checked against the INI
text by hand, and for every printer they offer.
"""

from __future__ import annotations

import math
import os
import stat
import tomllib
from pathlib import Path

import pytest

from rjcad.errors import BadInput
from rjcad.io import prusaslicer
from rjcad.io.prusaslicer import printer_names, printer_toml, profiles_dir, read_printer

REAL = Path("/usr/share/PrusaSlicer/profiles")
needs_real = pytest.mark.skipif(not REAL.is_dir(), reason=f"PrusaSlicer's bundles are not installed ({REAL})")
SCHEMA = {"name", "nozzle_mm", "layer_mm", "first_layer_mm", "bed_mm", "soluble_support", "source"}

# A vendor bundle as PrusaSlicer ships them (CRLF, `#` comments, quoted values, abstract `*…*` parents).
# [printer:Acme One 0.6] resolves through three levels: itself -> *one* -> *base*, plus *0.6nozzle*.
ACME = """\
# Acme test bundle
[vendor]
name = Acme
config_version = "0.9.1"

[printer_model:ONE]
name = Acme One
variants = 0.4; 0.6
technology = FFF

[printer_model:DUO]
variants = 0.4

[printer:*base*]
printer_technology = FFF
bed_shape = 0x0,200x0,200x180,0x180
max_print_height = 150
nozzle_diameter = 0.5
min_layer_height = 0.07
max_layer_height = 0.3
printer_model =
default_print_profile = 0.20mm BASE

[printer:*one*]
inherits = *base*
printer_model = ONE
bed_shape = 5x5,225x5,225x215,5x215
max_print_height = 240

[printer:*0.6nozzle*]
nozzle_diameter = 0.6
printer_variant = 0.6
max_print_height = 260
default_print_profile = "0.30mm DRAFT @ACME"

[printer:Acme One 0.6]
inherits = *one*; "*0.6nozzle*"
max_print_height = 255

[printer:Acme One Template]
inherits = *base*
printer_variant = 0.4

[printer:Acme Duo]
inherits = *base*
printer_model = DUO
printer_variant = 0.4
nozzle_diameter = 0.4, 0.4
default_print_profile = "0.15mm FINE @ACME"

[printer:Acme Resin]
printer_technology = SLA
printer_model = ONE
printer_variant = 0.4

[printer:Acme One 0.8]
inherits = *one*
printer_variant = 0.8

[printer:Acme One Bare]
inherits = *one*
printer_variant = 0.4
default_print_profile =

[printer:Acme One Stale]
inherits = *one*
printer_variant = 0.4
default_print_profile = 0.20mm NORMAL

[print:*common*]
layer_height = 0.2
first_layer_height = 0.3

[print:*0.30mm*]
inherits = *common*
layer_height = 0.3

[print:*draft*]
first_layer_height = 0.35

[print:0.30mm DRAFT @ACME]
inherits = *0.30mm*; *draft*

[print:0.15mm FINE @ACME]
inherits = *common*
layer_height = 0.15
first_layer_height = 150%

[print:0.20mm BASE]
inherits = *common*

[print:0.20mm NORMAL @ACME]
inherits = *common*

[print:0.20mm NORMAL @ACME XL]
inherits = *common*
"""


@pytest.fixture
def acme(tmp_path) -> Path:
    folder = tmp_path / "profiles"
    folder.mkdir()
    (folder / "Acme.ini").write_text(ACME, newline="\r\n")
    return folder


def one_line(error: pytest.ExceptionInfo) -> str:
    text = str(error.value)
    assert "\n" not in text and text.strip() == text
    return text


# ---------------------------------------------------------------- the synthetic bundle


def test_concrete_printers_leave_out_abstract_templates_sla_and_unknown_variants(acme):
    # *base*, *one*, *0.6nozzle*: abstract; Template: printer_model empty; Resin: SLA; 0.8: not a ONE variant
    assert printer_names(acme) == [
        ("Acme One 0.6", "Acme"),
        ("Acme Duo", "Acme"),
        ("Acme One Bare", "Acme"),
        ("Acme One Stale", "Acme"),
    ]


def test_three_level_inheritance_later_parent_and_own_keys_win(acme):
    p = read_printer("Acme One 0.6", acme)
    assert p["name"] == "Acme One 0.6" and p["vendor"] == "Acme"
    assert p["nozzle_mm"] == 0.6  # *0.6nozzle* (the later parent) over *base*'s 0.5 (reached through *one*)
    assert p["bed_mm"] == [220.0, 210.0, 255.0]  # *one*'s 5..225 x 5..215 over *base*; own z over 260 and 240
    assert p["print_profile"] == "0.30mm DRAFT @ACME"  # quoted in *0.6nozzle*
    assert p["layer_mm"] == 0.3  # [print:*0.30mm*] over *common*'s 0.2
    assert p["first_layer_mm"] == 0.35  # *draft* (later parent) over *common* reached through *0.30mm*
    assert p["extruders"] == 1
    assert p["source"] == (
        "PrusaSlicer vendor bundle Acme.ini 0.9.1: [printer:Acme One 0.6], "
        "default print profile [print:0.30mm DRAFT @ACME]"
    )
    assert "set in [printer:*0.6nozzle*]" in p["comments"]["nozzle_mm"]
    assert "set in [print:*draft*]" in p["comments"]["first_layer_mm"]


def test_percent_first_layer_and_per_extruder_nozzle_list(acme):
    p = read_printer("Acme Duo", acme)
    assert p["nozzle_mm"] == 0.4 and p["extruders"] == 2  # "0.4, 0.4": the first
    assert p["layer_mm"] == 0.15
    assert p["first_layer_mm"] == 0.225  # 150 % of 0.15
    assert p["bed_mm"] == [200.0, 180.0, 150.0]  # *base*
    assert "150% of layer_height" in p["comments"]["first_layer_mm"]
    text = printer_toml(p, "acme-duo")
    assert tomllib.loads(text)["soluble_support"] is False
    assert "2 extruders" in text and "set true if you load one" in text


def test_no_default_print_profile_takes_the_layer_range_midpoint_and_says_so(acme):
    p = read_printer("Acme One Bare", acme)
    assert p["layer_mm"] == p["first_layer_mm"] == 0.185  # (0.07 + 0.3) / 2
    assert p["print_profile"] == ""
    assert "midpoint" in p["comments"]["layer_mm"] and "no default print profile" in p["comments"]["layer_mm"]
    assert "min/max_layer_height" in p["source"]


def test_a_stale_default_print_profile_is_read_from_the_profiles_named_like_it(acme):
    # "0.20mm NORMAL" is not in the bundle; "0.20mm NORMAL @ACME" and "… @ACME XL" hold its words and agree
    p = read_printer("Acme One Stale", acme)
    assert (p["layer_mm"], p["first_layer_mm"]) == (0.2, 0.3)
    assert p["print_profile"] == "0.20mm NORMAL"
    assert "not in the bundle" in p["comments"]["layer_mm"] and "1 more named like it" in p["source"]


def test_name_matching_exact_case_insensitive_then_unique_part(acme):
    assert read_printer("acme duo", acme)["name"] == "Acme Duo"
    assert read_printer("STALE", acme)["name"] == "Acme One Stale"
    with pytest.raises(BadInput) as e:
        read_printer("Acme One", acme)  # in three names
    text = one_line(e)
    assert "is in 3 of the 4 PrusaSlicer printers" in text and "'Acme One Bare'" in text
    with pytest.raises(BadInput) as e:
        read_printer("Acme Dou", acme)
    text = one_line(e)
    assert text.startswith("no PrusaSlicer printer is named 'Acme Dou' (4 PrusaSlicer printers in ")
    assert "close: 'Acme Duo'" in text


def test_toml_round_trips_with_one_comment_per_value(acme):
    p = read_printer("Acme One 0.6", acme)
    text = printer_toml(p, "acme-one-0.6")
    data = tomllib.loads(text)
    assert set(data) == SCHEMA
    assert data == {
        "name": "Acme One 0.6",
        "nozzle_mm": 0.6,
        "layer_mm": 0.3,
        "first_layer_mm": 0.35,
        "bed_mm": [220.0, 210.0, 255.0],
        "soluble_support": False,
        "source": p["source"],
    }
    lines = text.splitlines()
    assert lines[0].startswith('# rjcad printer profile "acme-one-0.6", imported from PrusaSlicer')
    assert all("  # " in line for line in lines[1:]) and len(lines) == 1 + len(SCHEMA)
    assert "nozzle_mm = 0.6 " in text and "bed_mm = [220.0, 210.0, 255.0] " in text  # repr(float)


def test_toml_escapes_names_and_keeps_comments_on_one_line():
    printer = {
        "name": 'Odd "quoted" \\ name ü',
        "nozzle_mm": 0.25,
        "layer_mm": 0.1,
        "first_layer_mm": 1e-5 * 20000,
        "bed_mm": [250, 210.5, 1e3],
        "source": "made by hand",
        "comments": {"nozzle_mm": "two\nlines # with a hash"},
    }
    data = tomllib.loads(printer_toml(printer, "odd\nkey"))
    assert data["name"] == printer["name"] and data["bed_mm"] == [250.0, 210.5, 1000.0]
    assert data["first_layer_mm"] == 0.2


def test_broken_bundles_are_one_line_errors(tmp_path):
    cases = {
        "cycle": "[printer:*a*]\ninherits = *b*\n[printer:*b*]\ninherits = *a*\n[printer:P]\ninherits = *a*\n",
        "parent": "[printer:P]\ninherits = *missing*\n",
        "twice": "[printer:P]\nnozzle_diameter = 0.4\nnozzle_diameter = 0.6\n",
        "junk": "[printer:P]\nthis is not a key\n",
    }
    expected = {"cycle": "inherits itself", "parent": "not in the bundle", "twice": "twice", "junk": "line"}
    for name, text in cases.items():
        folder = tmp_path / name
        folder.mkdir()
        (folder / "V.ini").write_text(text)
        with pytest.raises(BadInput) as e:
            printer_names(folder)
        assert expected[name] in one_line(e)


# ---------------------------------------------------------------- finding the folder


def test_missing_profiles_are_one_line_naming_the_install_command(tmp_path, monkeypatch):
    with pytest.raises(BadInput) as e:
        profiles_dir(tmp_path / "nowhere")
    text = one_line(e)
    assert text == (
        f"PrusaSlicer's vendor profiles were not found (looked in {tmp_path / 'nowhere'}); "
        "install prusa-slicer (Debian: apt-get install prusa-slicer)"
    )
    monkeypatch.setenv("PATH", str(tmp_path))  # no executable
    monkeypatch.setattr(prusaslicer, "DEFAULT_DIR", tmp_path / "usr-share")
    with pytest.raises(BadInput) as e:
        printer_names()
    assert f"(looked in {tmp_path / 'usr-share'})" in one_line(e)


def test_the_folder_beside_the_executable_comes_first(tmp_path, acme, monkeypatch):
    prefix = tmp_path / "opt"
    (prefix / "bin").mkdir(parents=True)
    exe = prefix / "bin" / prusaslicer.EXECUTABLES[0]
    exe.write_text("#!/bin/sh\n")
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    share = prefix / "share" / "PrusaSlicer" / "profiles"
    share.parent.mkdir(parents=True)
    acme.rename(share)
    monkeypatch.setenv("PATH", str(prefix / "bin") + os.pathsep + os.environ.get("PATH", ""))
    assert profiles_dir() == share
    assert read_printer("Acme Duo")["vendor"] == "Acme"


# ---------------------------------------------------------------- the installed bundles

# (printer, bundle, its [vendor] config_version when checked by hand, nozzle, [x, y, z], layer, first layer)
# PrusaResearch.ini 1.5.1: [printer:Original Prusa i3 MK3S & MK3S+] inherits Original Prusa i3 MK3 (line 9239),
#   which sets max_print_height = 210 (9195) and default_print_profile = 0.15mm QUALITY @MK3 (9198) and
#   inherits *common*: nozzle_diameter = 0.4 (8819), bed_shape = 0x0,250x0,250x210,0x210 (8789).
#   [print:0.15mm QUALITY @MK3] inherits *0.15mm*; *MK3* (920): layer_height = 0.15 (497); *MK3* sets no
#   layer height; first_layer_height = 0.2 from [print:*common*] (167).
# The 0.6 nozzle: inherits Original Prusa i3 MK3 0.6 nozzle (9249): nozzle_diameter = 0.6 (9214),
#   default_print_profile = 0.30mm QUALITY @0.6 nozzle MK3 (9220), which inherits *0.30mm*; *0.6nozzleMK3*;
#   *MK306* (1138): layer_height = 0.3 (537); none of them sets first_layer_height: *common*'s 0.2 (167).
# Creality.ini 0.2.1: [printer:Creality Ender-3 (0.4 mm nozzle)] inherits *ENDER3*; *0.4nozzle* (1238):
#   bed_shape = 3x3,228x3,228x228,3x228 (1229) -> 225 x 225, max_print_height = 250 (1230),
#   nozzle_diameter = 0.4 (1202), default_print_profile = "0.16 mm OPTIMAL (0.4 mm nozzle) @CREALITY" (1207,
#   quoted), which inherits *0.16mm*; *0.4nozzle* (665): layer_height = 0.16 (508), first_layer_height = 0.2
#   (563, over *common*'s 0.2 at 415).
# Voron.ini 1.0.0: [printer:Voron_v2_250 0.4 nozzle] inherits *Voron_v2_250*; *0.4nozzle* (303): bed 250 x 250
#   x 250 (241-242), nozzle 0.4 (120); its default_print_profile = 0.15mm 0.4nozzle (125) is not in the
#   bundle: [print:0.15mm 0.4nozzle V0/V1/V2] (1125, 1101, 1069) inherit *0.15mm* (layer_height = 0.15, 894)
#   and *0.4nozzle* (first_layer_height = 0.2, 777, over *common*'s 75 %, 655).
HAND_CHECKED = [
    ("Original Prusa i3 MK3S & MK3S+", "PrusaResearch", "1.5.1", 0.4, [250.0, 210.0, 210.0], 0.15, 0.2),
    ("Original Prusa i3 MK3S & MK3S+ 0.6 nozzle", "PrusaResearch", "1.5.1", 0.6, [250.0, 210.0, 210.0], 0.3, 0.2),
    ("Creality Ender-3 (0.4 mm nozzle)", "Creality", "0.2.1", 0.4, [225.0, 225.0, 250.0], 0.16, 0.2),
    ("Voron_v2_250 0.4 nozzle", "Voron", "1.0.0", 0.4, [250.0, 250.0, 250.0], 0.15, 0.2),
]


@needs_real
@pytest.mark.parametrize(("name", "vendor", "version", "nozzle", "bed", "layer", "first"), HAND_CHECKED)
def test_real_printers_match_the_ini_read_by_hand(name, vendor, version, nozzle, bed, layer, first):
    p = read_printer(name, REAL)
    if f" {vendor}.ini {version}:" not in p["source"]:
        pytest.skip(f"{vendor}.ini is not version {version}, whose values were checked by hand: {p['source']}")
    assert (p["vendor"], p["nozzle_mm"], p["bed_mm"], p["layer_mm"], p["first_layer_mm"]) == (
        vendor,
        nozzle,
        bed,
        layer,
        first,
    )
    data = tomllib.loads(printer_toml(p, "real"))
    assert set(data) == SCHEMA and data["bed_mm"] == bed and data["layer_mm"] == layer


@needs_real
def test_every_real_printer_resolves_within_bounds():
    names = printer_names(REAL)
    vendors = {v for _, v in names}
    # the Ditto modes of the BIBO 2 (both heads print copies side by side) limit the bed to a 33 mm strip
    # (BIBO.ini: bed_shape = 0x-93,33x-93,33x93,0x93): legitimately under the 50 mm bound
    ditto = {"BIBO2 E1 right E2 Ditto", "BIBO2 E2 left E1 Ditto"}
    builtin = []
    for name, vendor in names:
        p = read_printer(name, REAL)
        assert p["vendor"] == vendor
        assert 0.1 < p["nozzle_mm"] <= 1.2, p
        assert min(p["bed_mm"][:2]) > (30 if name in ditto else 50) and p["bed_mm"][2] > 50, p
        assert 0 < p["layer_mm"] <= p["nozzle_mm"] and 0 < p["first_layer_mm"] <= p["nozzle_mm"], p
        assert all(math.isfinite(v) for v in p["bed_mm"])
        if any("built-in default" in c for c in p["comments"].values()):
            builtin.append(name)
        assert set(tomllib.loads(printer_toml(p, "k"))) == SCHEMA
    print(f"{len(names)} printers from {len(vendors)} bundles resolved; built-in defaults used by {builtin}")
    assert len(names) >= 300 and len(vendors) >= 15  # 383 from 18 bundles with prusa-slicer 2.5.0
    # bed_shape unset for the CR-20s, nozzle_diameter for the Anycubic i3 Megas (PrusaSlicer then uses its own)
    assert len(builtin) <= 12


@needs_real
def test_profiles_dir_finds_an_installed_folder():
    assert any(profiles_dir().glob("*.ini"))


@needs_real
def test_real_wrong_name_lists_close_printers():
    with pytest.raises(BadInput) as e:
        read_printer("Creality Ender 3 V2 0.4", REAL)
    text = one_line(e)
    assert text.startswith("no PrusaSlicer printer is named 'Creality Ender 3 V2 0.4' (")
    assert "close: 'Creality Ender-3 V2" in text
    with pytest.raises(BadInput) as e:
        read_printer("Ender-3", REAL)
    assert "give more of the name" in one_line(e)
