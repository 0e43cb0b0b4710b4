"""Untrusted input (rjcad/io/untrusted.py and its readers): every bad file or value is one short error line, exit 2.

Classes of issue #17: integers too large for a float, deep nesting, binary and UTF-16 files, NaN, strings and
booleans where numbers belong, huge values echoed into the error, malformed manifests, bad sweep files, a
clearance below the printer's minimum gap, `rjcad check` float options, warnings on stderr, radians in a
theta_deg column, and campaign data files outside the campaign's folder.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
import trimesh

from rjcad.errors import ParameterError, RjcadError, quote
from rjcad.io import untrusted

DEG = math.pi / 180
BIG_INT = "1" + "0" * 400


def error_line(r, *words: str) -> str:
    """The one stderr line of a run that stopped at bad input, checked: exit 2, no output, names ``words``."""
    lines = r.err.splitlines()
    assert r.code == 2 and len(lines) == 1, r.err[-2000:]
    line = lines[0]
    assert line.startswith("rjcad: error: ") and "Traceback" not in line and "Warning" not in line
    assert len(line) < 400, line[:500]
    for w in words:
        assert w in line, (w, line)
    return line


# ---------------------------------------------------------------- the module


@pytest.mark.parametrize(
    "raw, words",
    [
        (b"\xff\xfea\x00=\x001\x00", "UTF-16 text; save the TOML file as UTF-8"),
        (b"a = 1\n\x00\x01\x02", "holds NUL bytes: a binary file, not a TOML file"),
        (b'a = "\xe9"\n', "not a UTF-8 text file (byte 0xe9 on line 1)"),
        (b"\xef\xbb\xbfa = 1\r\nb = 2\r\n", None),  # a BOM and CRLF are fine
    ],
)
def test_decoding(tmp_path, raw, words):
    f = tmp_path / "x.toml"
    f.write_bytes(raw)
    if words is None:
        assert untrusted.read_toml(f) == {"a": 1, "b": 2}
        return
    with pytest.raises(RjcadError) as e:
        untrusted.read_toml(f)
    assert str(e.value) == f"{f}: {words}"


def test_size_missing_and_directory(tmp_path, monkeypatch):
    monkeypatch.setitem(untrusted.MAX_BYTES, "TOML", 100)
    f = tmp_path / "x.toml"
    f.write_text("a = 1\n" * 20)
    with pytest.raises(RjcadError, match=r"x\.toml: too large: a TOML file must be at most 100 bytes$"):
        untrusted.read_toml(f)
    with pytest.raises(RjcadError, match=r"nope\.toml: file not found$"):
        untrusted.read_toml(tmp_path / "nope.toml")
    with pytest.raises(RjcadError, match="is a directory"):
        untrusted.read_toml(tmp_path)


@pytest.mark.parametrize(
    "text, words",
    [
        ("a = " + "[" * 3000 + "]" * 3000, "nested deeper than 32"),  # tomllib's recursion
        ("[" + ".".join(["t"] * 40) + "]\nx = 1", "nests deeper than 32"),  # parsed, then measured
        ("x = " + "{a = " * 3000 + "1" + "}" * 3000, "nested deeper than 32"),
        (f"[k]\nstiffness = {BIG_INT}", "k.stiffness = <an integer of 401 digits> is invalid: must fit a float"),
        ("x = " + "9" * 5000, "not valid TOML"),  # beyond Python's 4300 digits
        ("[k]\nv = [1, nan]", "k.v[2] = nan is invalid: must be a finite number"),
        ("v = -inf", "v = -inf is invalid: must be a finite number"),
        ("v = 1e400", "v = inf is invalid"),
    ],
)
def test_toml_structure(tmp_path, text, words):
    f = tmp_path / "x.toml"
    f.write_text(text)
    with pytest.raises(RjcadError) as e:
        untrusted.read_toml(f)
    msg = str(e.value)
    assert msg.startswith(f"{f}: ") and words in msg and len(msg) < 300 and "\n" not in msg


@pytest.mark.parametrize(
    "text, words",
    [
        ("[" * 5000 + "]" * 5000, "nested deeper than 32"),
        ('{"a": {"b": [1, NaN]}}', "a.b[2] = nan is invalid: must be a finite number"),
        ('{"a": 1e400}', "a = inf is invalid"),
        ('{"a": Infinity}', "a = inf is invalid"),
        ('{"a": ' + BIG_INT + "}", "a = <an integer of 401 digits>"),
        ("{not json", "not valid JSON (Expecting property name enclosed in double quotes at line 1, column 2)"),
    ],
)
def test_json_structure(tmp_path, text, words):
    f = tmp_path / "x.json"
    f.write_text(text)
    with pytest.raises(RjcadError) as e:
        untrusted.read_json(f)
    assert str(e.value).startswith(f"{f}: ") and words in str(e.value)


def test_confined_keeps_files_in_the_folder(tmp_path):
    (tmp_path / "c" / "data").mkdir(parents=True)
    (tmp_path / "c" / "data" / "a.csv").write_text("x")
    (tmp_path / "secret.csv").write_text("x")
    (tmp_path / "c" / "link.csv").symlink_to(tmp_path / "secret.csv")
    folder = tmp_path / "c"
    assert untrusted.confined(folder, "data/a.csv", "c.toml") == folder / "data" / "a.csv"
    for name in ("../secret.csv", str(tmp_path / "secret.csv"), "link.csv", "data/../../secret.csv"):
        with pytest.raises(RjcadError, match=r"is outside .* \(or pass --allow-outside\)"):
            untrusted.confined(folder, name, "c.toml")
        assert untrusted.confined(folder, name, "c.toml", allow_outside=True) == folder / name


def test_quote_cuts_values_short():
    assert quote("x" * 50_000_000) == "'" + "x" * 59 + "…"
    assert quote(10**5000) == "<an integer of 5001 digits>"
    assert quote([10**5000, "a"]) == "[<an integer of 5001 digits>, 'a']"
    assert quote(0.25) == "0.25" and quote(True) == "True" and quote("pla") == "'pla'"
    e = ParameterError("material", "q" * 50_000_000, "known materials: pla")
    assert len(str(e)) < 120 and str(e).endswith("… is invalid: known materials: pla")


def test_a_long_parameter_name_keeps_its_key():
    """A name built from a deep path and a key is cut in the middle: the key, at its end, stays whole."""
    name = "/" + "deep/" * 60 + "campaign.toml: experiment 1 (exp1.csv): normal_load_n"
    text = str(ParameterError(name, -1.0, "must be >= 0"))
    assert text.endswith(": normal_load_n = -1 is invalid: must be >= 0") and text.startswith("/deep/")
    assert "…" in text and len(text) < 300
    huge = str(ParameterError("k" * 50_000_000 + "\nkey", 1.0, "unknown"))
    assert len(huge) < 300 and huge.endswith("k key = 1 is invalid: unknown")


# ---------------------------------------------------------------- every command's files


def _campaign(folder, top=90.0, radians=False, file="exp1.csv", write_csv=True):
    """A one-experiment bar campaign: 3 triangles 0 → ``top`` deg, torque = 5.2·(θ + 70°) ± 0.3 N·mm of friction;
    the theta_deg column in radians if ``radians``."""
    folder.mkdir(parents=True, exist_ok=True)
    n = 600
    phase = np.linspace(0, 3, n, endpoint=False) % 1
    theta = top * (1 - np.abs(2 * phase - 1))
    direction = np.where(phase < 0.5, 1.0, -1.0)
    torque = 5.2 * (theta + 70) * DEG + 0.3 * direction + np.random.default_rng(0).normal(0, 0.01, n)
    column = np.radians(theta) if radians else theta
    if write_csv:
        rows = "\n".join(f"{0.01 * i:.2f},{a:.6f},{b:.6f}" for i, (a, b) in enumerate(zip(column, torque)))
        (folder / file).write_text("t_s,theta_deg,torque_nmm\n" + rows + "\n")
    toml = folder / "campaign.toml"
    toml.write_text(
        "[design]\nstiffness_nmm_per_rad = 5.2\npreload_deg = 70\npulley_radius_mm = 6\n"
        f'[[experiment]]\nfile = "{file}"\ndrive = "bar"\n'
    )
    return toml


#: TOML contents no command may choke on, with what the error line must say.
BAD_TOML = {
    "big_int": (f"stiffness_nmm_per_rad = {BIG_INT}\n", "must fit a float"),
    "deep_arrays": ("a = " + "[" * 3000 + "]" * 3000 + "\n", "nested deeper than 32"),
    "deep_tables": ("[" + ".".join(["t"] * 3000) + "]\n", "nests deeper than 32"),
    "nan": ("stiffness_nmm_per_rad = nan\n", "must be a finite number"),
    "garbage": (bytes(range(256)) * 20, "NUL bytes"),
    "utf16": ("stiffness_nmm_per_rad = 5\n".encode("utf-16"), "UTF-16"),
}
#: Each command that reads a TOML file: its arguments around the file.
TOML_COMMANDS = {
    "spring": lambda f: ["spring", "--config", f],
    "joint": lambda f: ["joint", "--config", f, "--out", f + ".out"],
    "finger": lambda f: ["finger", f, "--out", f + ".out"],
    "sweep": lambda f: ["sweep", f, "--out", f + ".out"],
    "identify": lambda f: ["identify", f],
    "simulate finger": lambda f: ["simulate", "finger", f],
}


@pytest.mark.parametrize("command", TOML_COMMANDS)
@pytest.mark.parametrize("case", BAD_TOML)
def test_every_toml_reader_refuses_bad_files_in_one_line(tmp_path, cli, command, case):
    content, words = BAD_TOML[case]
    f = tmp_path / "in.toml"
    f.write_bytes(content if isinstance(content, bytes) else content.encode())
    r = cli(TOML_COMMANDS[command](str(f)))
    assert r.code == 2
    error_line(r, str(f), words)
    assert r.out == "" and not (tmp_path / "in.toml.out").exists()


def test_huge_string_values_are_quoted_short(tmp_path, cli):
    f = tmp_path / "j.toml"
    f.write_text(f'material = "{"q" * 900_000}"\n')
    r = cli("spring", "--config", f, "--stiffness", "5")
    assert r.code == 2
    error_line(r, "material = 'qqq", "…", "known materials")
    f.write_text(f'[params.material]\nvalues = ["pla", {"7" * 300}]\n')
    r = cli("sweep", f, "--out", tmp_path / "o")
    assert r.code == 2
    error_line(r, "j.toml: params.material.values[2] = <an integer of 300 digits>")
    r = cli("spring", "--stiffness", "5", "--material", "m" * 200_000)
    assert r.code == 2
    error_line(r, "material = 'mmm")


# ---------------------------------------------------------------- manifests (rjcad check --manifest)


@pytest.fixture
def two_boxes(tmp_path):
    """A two-body STL (boxes of 1000 and 500 mm³, 2 mm apart) and a sound manifest for it."""
    a = trimesh.creation.box((10, 10, 10))
    b = trimesh.creation.box((10, 10, 5))
    b.apply_translation((12, 0, 0))
    stl = tmp_path / "two.stl"
    trimesh.util.concatenate([a, b]).export(stl)
    manifest = {
        "schema_version": 1,
        "printer": "generic-0.4",
        "clearance_mm": 0.25,
        "bodies": [{"name": "a", "volume_mm3": 1000.0}, {"name": "b", "volume_mm3": 500.0}],
        "joints": [
            {"parent": "a", "child": "b", "axis_point_mm": [0, 0, 0], "axis_dir": [0, 0, 1], "rotation_deg": 10.0}
        ],
    }
    return stl, manifest


def _edit(path):
    def edit(m):
        target = m
        for k in path[:-1]:
            target = target[k]
        if path[-1] in target and isinstance(target, dict):
            del target[path[-1]]

    return edit


MANIFESTS = [  # (name, edit of the JSON object or the file's bytes, words the error names)
    ("a JSON list", lambda m: [m], "manifest must be a JSON object, not an array"),
    ("binary garbage", bytes(range(256)) * 8, "NUL bytes"),
    ("UTF-16", lambda m: json.dumps(m).encode("utf-16"), "UTF-16"),
    ("no volume", _edit(["bodies", 0, "volume_mm3"]), "bodies[1].volume_mm3 is required"),
    (
        "string volume",
        lambda m: m["bodies"][1].update(volume_mm3="500"),
        "bodies[2].volume_mm3 must be a finite number",
    ),
    ("no bodies", _edit(["bodies"]), "bodies is required with an STL mesh"),
    ("no axis", _edit(["joints", 0, "axis_dir"]), "joints[1].axis_dir is required for the motion check"),
    ("zero axis", lambda m: m["joints"][0].update(axis_dir=[0, 0, 0]), "joints[1].axis_dir must be a non-zero"),
    ("NaN volume", lambda m: m["bodies"][0].update(volume_mm3=math.nan), "bodies[1].volume_mm3 = nan is invalid"),
    ("NaN clearance", lambda m: m.update(clearance_mm=math.nan), "clearance_mm = nan is invalid"),
    ("zero clearance", lambda m: m.update(clearance_mm=0), "clearance_mm must be in [0.1, 5] mm, not 0"),
    ("huge rotation", lambda m: m["joints"][0].update(rotation_deg=1e9), "joints[1].rotation_deg must be in (0, 360]"),
    ("no joints list", lambda m: m.update(joints="x"), "joints must be a list"),
    ("deep", lambda m: m.update(extra=json.loads("[" * 100 + "]" * 100)), "nests deeper than 32"),
]


@pytest.mark.parametrize("name, edit, words", MANIFESTS, ids=[c[0] for c in MANIFESTS])
def test_bad_manifests_are_one_line_naming_the_file_and_key(tmp_path, cli, two_boxes, name, edit, words):
    stl, manifest = two_boxes
    f = tmp_path / "m.json"
    if isinstance(edit, bytes):
        f.write_bytes(edit)
    else:
        out = edit(manifest)
        data = manifest if out is None else out
        f.write_bytes(data if isinstance(data, bytes) else json.dumps(data).encode())
    r = cli("check", stl, "--manifest", f)
    assert r.code == 2
    error_line(r, f"{f}: ", words)


def test_a_sound_manifest_passes(cli, tmp_path, two_boxes):
    stl, manifest = two_boxes
    (tmp_path / "m.json").write_text(json.dumps(manifest))
    r = cli("check", stl, "--manifest", tmp_path / "m.json", "--json")
    assert r.code in (0, 1) and r.err == ""
    assert {c["name"]: c["passed"] for c in json.loads(r.out)["checks"]}["motion"] is True


@pytest.mark.parametrize(
    "option, value, words",
    [
        ("--clearance", "-1", "--clearance = -1 mm is invalid: must be in [0.1, 5] mm"),
        ("--clearance", "0", "--clearance = 0 mm"),
        ("--clearance", "nan", "--clearance = nan mm"),
        ("--clearance", "inf", "--clearance = inf mm"),
        ("--clearance", "6", "--clearance = 6 mm"),
        ("--clearance", "0.2", "must be >= 0.25 mm on generic-0.4"),
        ("--allowance", "nan", "--allowance = nan mm is invalid: must be in [0, 0.05] mm"),
        ("--allowance", "-0.01", "--allowance = -0.01 mm"),
    ],
)
def test_check_float_options_are_validated_first(cli, tmp_path, two_boxes, option, value, words):
    stl, _ = two_boxes
    r = cli("check", stl, option, value)
    assert r.code == 2
    error_line(r, words)


# ---------------------------------------------------------------- values accepted that should not be


def test_clearance_below_the_printers_minimum_gap_is_refused(cli, tmp_path):
    r = cli("joint", "--clearance", "0.2", "--out", tmp_path / "j")
    assert r.code == 2
    error_line(r, "clearance = 0.2 mm", ">= 0.25 mm on generic-0.4")
    r = cli("joint", "--clearance", "0.24", "--printer", "dimension-elite", "--out", tmp_path / "j")
    assert r.code == 2
    error_line(r, "on dimension-elite")
    t = tmp_path / "f.toml"
    t.write_text("clearance_mm = 0.2\n[[joint]]\nstiffness_nmm_per_rad = 5.2\n")
    r = cli("finger", t, "--out", tmp_path / "f")
    assert r.code == 2
    error_line(r, "f.toml: clearance_mm = 0.2 mm", ">= 0.25 mm")
    assert not (tmp_path / "j").exists() and not (tmp_path / "f").exists()


def _warned(cli, args):
    """The run and the warnings raised during it (pytest would otherwise keep them from stderr)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = cli(args)
    return r, [str(w.message) for w in caught]


def test_tiny_values_give_no_warning(cli):
    for args in (
        ["spring", "--stiffness", "5e-324"],
        ["spring", "--stiffness", "5", "--rotation", "1e-300"],
        ["spring", "--stiffness", "5", "--max-outer-radius", "5e-324"],
        ["simulate", "joint", "--rotation", "60", "--preload", "1e300"],
    ):
        r, caught = _warned(cli, ["--debug"] + args)  # --debug shows warnings: the cause is fixed, not hidden
        assert r.code == 2 and caught == [], caught
        r = cli(args)
        assert r.code == 2
        error_line(r, "is invalid")


def test_stray_warnings_are_shown_with_debug_only(cli, monkeypatch):
    import rjcad.cli.spring as spring_cli

    def noisy(req):
        warnings.warn("something numpy says", RuntimeWarning, stacklevel=2)
        raise RjcadError("no spring")

    monkeypatch.setattr(spring_cli, "design_spring", noisy)
    r, caught = _warned(cli, ["spring", "--stiffness", "5"])
    assert r.code == 2 and caught == []
    error_line(r, "no spring")
    r, caught = _warned(cli, ["--debug", "spring", "--stiffness", "5"])
    assert r.code == 2 and caught == ["something numpy says"]


# ---------------------------------------------------------------- sweep files

SWEEPS = [  # (file text, the key the error names)
    ("[fixed]\npreload_deg = true\n", "fixed.preload_deg = True is invalid: must be a number"),
    ("[fixed]\nrotation_deg = '90'\n", "fixed.rotation_deg = '90' is invalid: must be a number"),
    ("[params.stiffness_nmm_per_rad]\nvalues = [2, 'x', 4]\n", "params.stiffness_nmm_per_rad.values[2] = 'x'"),
    ("[params.stiffness_nmm_per_rad]\nrange = [2]\nsteps = 3\n", "params.stiffness_nmm_per_rad.range = [2]"),
    ("[params.stiffness_nmm_per_rad]\nrange = [true, 4]\nsteps = 3\n", "params.stiffness_nmm_per_rad.range[1] = True"),
    ("[params.stiffness_nmm_per_rad]\nrange = [2, 4]\nsteps = '3'\n", "params.stiffness_nmm_per_rad.steps = '3'"),
    ("[params.stiffness_nmm_per_rad]\nrange = [2, 4]\nsteps = 2.5\n", "params.stiffness_nmm_per_rad.steps = 2.5"),
    ("[sweep]\nmode = 'lhs'\nsamples = '10'\n[params.rotation_deg]\nrange = [20, 90]\n", "sweep.samples = '10'"),
    ("[sweep]\nmode = 'lhs'\nsamples = 10\nseed = '1'\n", "sweep.seed = '1'"),
    ("[sweep]\nmode = 'lhs'\nsamples = 10\nseed = -1\n", "sweep.seed = -1"),
    ("[params.stiffness_nmm_per_rad]\nvalues = 5\n", "params.stiffness_nmm_per_rad.values = 5"),
    ("[sweep]\nmode = 'lhs'\nsamples = 10\n[params.material]\nvalues = []\n", "params.material.values = []"),
    ("[params.material]\nvalues = [3]\n", "params.material.values[1] = 3 is invalid: must be a string"),
    ("[params.material]\nrange = [1, 2]\nsteps = 2\n", "params.material.range"),
    ("[fixed]\nmaterial = 'pla'\n[params.material]\nvalues = ['pla']\n", "fixed.material"),
    ("[params]\nrotation_deg = 3\n", "params.rotation_deg = 3 is invalid: must be a table"),
    (
        "[params.stiffness_nmm_per_rad]\nrange = [2, 4]\nsteps = 100000\n[params.rotation_deg]\nrange = [20, 90]\n"
        "steps = 1000\n",
        "params.rotation_deg = 1000 is invalid: makes the grid 100000000 designs",
    ),
]


@pytest.mark.parametrize("text, words", SWEEPS)
def test_bad_sweep_files_are_one_line_before_any_output(cli, tmp_path, text, words):
    f = tmp_path / "s.toml"
    f.write_text(text)
    r = cli("sweep", f, "--out", tmp_path / "out")
    assert r.code == 2
    error_line(r, f"s.toml: {words}")
    assert not (tmp_path / "out").exists()


def test_bad_designs_are_rows_with_their_error(tmp_path):
    import io

    from rjcad import sweep as sw

    spec = sw.SweepSpec.from_dict(
        {"params": {"clearance_mm": {"values": [-3.0, 0.2, 0.3]}, "link_length_mm": {"values": [40.0, -1.0]}}}
    )
    rows = {
        (r["clearance_mm"], r["link_length_mm"]): r for r in sw.run_sweep(spec, tmp_path, stream=io.StringIO()).rows
    }
    assert rows[(-3.0, 40.0)]["status"] == "failed" and "clearance_mm = -3 mm" in rows[(-3.0, 40.0)]["error"]
    assert rows[(0.2, 40.0)]["status"] == "failed" and ">= 0.25 mm on generic-0.4" in rows[(0.2, 40.0)]["error"]
    assert rows[(0.3, -1.0)]["status"] == "failed" and "link_length_mm = -1 mm" in rows[(0.3, -1.0)]["error"]
    assert rows[(0.3, 40.0)]["status"] == "ok"


# ---------------------------------------------------------------- identify: units and where the data lie


def test_radians_in_a_degree_column_are_refused(cli, tmp_path):
    from rjcad.identify.data import load_campaign

    assert len(load_campaign(_campaign(tmp_path / "deg")).experiments) == 1
    r = cli("identify", _campaign(tmp_path / "rad", radians=True))
    assert r.code == 2
    error_line(r, "exp1.csv: column theta_deg looks like radians", "±1.57", "theta_deg must be in degrees")
    # a small motion in degrees, against friction larger than its spring torque, is not radians
    assert load_campaign(_campaign(tmp_path / "small", top=3.0)).experiments
    r = cli("identify", _campaign(tmp_path / "small_rad", top=3.0 / DEG, radians=True))  # 3 rad: 172°
    assert r.code == 2
    error_line(r, "looks like radians", "±3.00")


def test_identify_reads_only_files_in_the_campaigns_folder(cli, tmp_path):
    _campaign(tmp_path, file="outside.csv")  # a good data file, one level up
    for name in ("/etc/passwd", "../../../../../../../etc/passwd", "../outside.csv", "link.csv"):
        toml = _campaign(tmp_path / "c", file=name, write_csv=False)
        if name == "link.csv":
            (tmp_path / "c" / "link.csv").unlink(missing_ok=True)
            (tmp_path / "c" / "link.csv").symlink_to(tmp_path / "outside.csv")
        r = cli("identify", toml)
        assert r.code == 2
        line = error_line(r, "campaign.toml: experiment 1: file", "is outside", "--allow-outside")
        assert "root" not in line.replace(str(tmp_path), "")
    toml = _campaign(tmp_path / "c", file="/etc/passwd", write_csv=False)
    r = cli("identify", toml, "--allow-outside")
    assert r.code == 2
    line = error_line(r, "/etc/passwd: missing columns", "first line is not a header")
    assert "root" not in line and "/bin" not in line.replace("/etc/passwd", "")


@pytest.mark.parametrize("effects, rotation", [("paper", 90.0), ("all", 3.0), ("all", 180.0), ("none", 1.5)])
def test_bench_campaigns_in_degrees_pass_and_in_radians_are_refused(tmp_path, effects, rotation):
    from rjcad.identify.bench import PAPER_PRESET, write_campaign
    from rjcad.identify.catalogue import CATALOGUE
    from rjcad.identify.data import load_campaign

    chosen, params, design = {
        "paper": (list(PAPER_PRESET["effects"]), PAPER_PRESET["params"], PAPER_PRESET["design"]),
        "all": ([e.id for e in CATALOGUE if e.needs != "bearing"], {}, None),  # the bearing needs a built joint
        "none": ([], {}, None),
    }[effects]
    write_campaign(tmp_path, chosen, params, design=design, seed=2, samples=600, rotation_deg=rotation)
    assert len(load_campaign(tmp_path / "campaign.toml").experiments) == 5
    if rotation < 60:
        return  # in radians it moves less than 1 "degree": refused as too small a motion already
    for csv in tmp_path.glob("*.csv"):
        lines = csv.read_text().splitlines()
        rows = [line.split(",") for line in lines[1:]]
        csv.write_text("\n".join([lines[0]] + [f"{t},{math.radians(float(a)):.6f},{y}" for t, a, y in rows]) + "\n")
    with pytest.raises(RjcadError, match=r"^A_bar_\S+\.csv: column theta_deg looks like radians"):
        load_campaign(tmp_path / "campaign.toml")
