"""Campaign loading (rjcad.identify.data): the pinned TOML + CSV format and one-line errors."""

import math
import re

import numpy as np
import pytest

import rjcad.cli
from rjcad.errors import ParameterError, RjcadError
from rjcad.identify.data import load_campaign

DEG = math.pi / 180

DESIGN = """\
[design]
stiffness_nmm_per_rad = 5.2
preload_deg = 70
pulley_radius_mm = 6
"""


def triangle(n=600, cycles=3, top=90.0):
    """Joint angle [deg]: ``cycles`` triangles 0 → top → 0 over ``n`` samples."""
    phase = np.linspace(0, cycles, n, endpoint=False) % 1
    return top * (1 - np.abs(2 * phase - 1))


def columns(n=600, drive="bar", theta=None, seed=0):
    """Synthetic columns: t [s], theta [deg], torque = 5.2·(θ + 70°) [N·mm] (or force = torque / 6 mm) + noise."""
    rng = np.random.default_rng(seed)
    theta = triangle(n) if theta is None else np.asarray(theta, dtype=float)
    t = np.arange(len(theta)) * 0.01
    torque = 5.2 * (theta + 70) * DEG + rng.normal(0, 0.01, len(theta))
    if drive == "bar":
        return {"t_s": t, "theta_deg": theta, "torque_nmm": torque}
    return {"t_s": t, "theta_deg": theta, "tendon_force_n": torque / 6}


def write_csv(path, cols, header=None, comments=()):
    names = list(cols)
    lines = list(comments) + [header if header is not None else ",".join(names)]
    rows = np.column_stack([np.asarray(cols[k], dtype=float) for k in names])
    lines += [",".join(f"{v:.6f}" for v in row) for row in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def write_campaign(tmp_path, experiments=None, design=DESIGN, name="campaign.toml"):
    """A campaign TOML; ``experiments`` is TOML text of the [[experiment]] tables (default: one bar experiment)."""
    if experiments is None:
        write_csv(tmp_path / "exp1.csv", columns())
        experiments = '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n'
    toml = tmp_path / name
    toml.write_text(design + "\n" + experiments)
    return toml


def error(toml, kind=RjcadError):
    """The message of the error loading ``toml`` raises; it must be one line."""
    with pytest.raises(kind) as info:
        load_campaign(toml)
    msg = str(info.value)
    assert "\n" not in msg and msg.strip() == msg and msg
    return msg


def csv_error(tmp_path, lines, drive="bar"):
    """The error for a CSV file written verbatim from ``lines``."""
    (tmp_path / "exp1.csv").write_text("\n".join(lines) + "\n")
    toml = write_campaign(tmp_path, f'[[experiment]]\nfile = "exp1.csv"\ndrive = "{drive}"\n')
    msg = error(toml)
    assert msg.startswith("exp1.csv: ")
    return msg


def data_lines(cols):
    names = list(cols)
    rows = np.column_stack([cols[k] for k in names])
    return [",".join(names)] + [",".join(f"{v:.6f}" for v in row) for row in rows]


# ---- a good campaign ----


def test_good_campaign_loads_values_defaults_and_units(tmp_path):
    bar = columns()
    bar["force"] = np.zeros(600)  # extra columns are ignored
    write_csv(tmp_path / "exp1_bar.csv", bar, comments=["# rig 2, camera 60 fps", "#"])
    tendon = columns(drive="tendon", seed=1)
    tendon = {"frame": np.arange(600), **tendon}  # columns in any order
    write_csv(tmp_path / "exp2_tendon.csv", tendon, header=" frame ,  t_s,theta_deg ,tendon_force_n ")
    text = (tmp_path / "exp2_tendon.csv").read_text().split("\n")
    text.insert(10, "# a comment between data rows")
    text.insert(20, "")  # blank lines are skipped too
    (tmp_path / "exp2_tendon.csv").write_text("\n".join(text))
    toml = write_campaign(
        tmp_path,
        """
[[experiment]]
file = "exp1_bar.csv"
drive = "bar"

[[experiment]]
file = "exp2_tendon.csv"
drive = "tendon"
normal_load_n = 1.5
routed = true
pulley_radius_mm = 4.5
""",
    )
    c = load_campaign(toml)
    assert c.path == toml and c.notes == ()
    assert c.design.stiffness == 5.2 and c.design.pulley_radius == 6.0
    assert c.design.preload == pytest.approx(70 * DEG)
    assert c.design.as_json()["preload_deg"] == pytest.approx(70)
    e1, e2 = c.experiments
    assert (e1.file, e1.drive, e1.normal_load, e1.routed, e1.pulley_radius) == ("exp1_bar.csv", "bar", 0.0, False, 6.0)
    assert e1.path == tmp_path / "exp1_bar.csv" and e1.name == "exp1_bar"
    assert e1.rows == 600 and e1.dropped == {}
    np.testing.assert_allclose(e1.theta, np.round(triangle(), 6) * DEG, atol=1e-12)
    np.testing.assert_allclose(e1.y, np.round(bar["torque_nmm"], 6), atol=1e-12)
    np.testing.assert_allclose(e1.t, np.round(bar["t_s"], 6), atol=1e-12)
    assert (e2.drive, e2.normal_load, e2.routed, e2.pulley_radius) == ("tendon", 1.5, True, 4.5)
    assert e2.quantity == "tendon_force_n" and e2.setup.routed and e2.setup.normal_load == 1.5
    assert e2.rows == 600 and len(e2.t) == 600
    np.testing.assert_allclose(e2.y, np.round(tendon["tendon_force_n"], 6), atol=1e-12)
    for e in c.experiments:
        assert e.t.dtype == e.theta.dtype == e.y.dtype == np.float64


def test_paths_are_relative_to_the_toml_file(tmp_path, monkeypatch):
    (tmp_path / "data").mkdir()
    write_csv(tmp_path / "data" / "exp1.csv", columns())
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "data/exp1.csv"\ndrive = "bar"\n')
    monkeypatch.chdir(tmp_path / "data")  # not where the TOML is
    c = load_campaign(toml)
    assert c.experiments[0].name == "exp1" and len(c.experiments[0].t) == 600


def test_crlf_and_byte_order_mark_are_read(tmp_path):
    text = "\r\n".join(data_lines(columns())) + "\r\n"
    (tmp_path / "exp1.csv").write_bytes(b"\xef\xbb\xbf" + text.encode())
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n')
    assert len(load_campaign(toml).experiments[0].t) == 600


def test_noisy_angles_with_holds_count_as_moving_back_and_forth(tmp_path):
    rng = np.random.default_rng(3)
    ramp = np.linspace(0, 4, 200)  # a small 4° motion with holds, 0.3° camera noise
    theta = np.concatenate([np.zeros(100), ramp, np.full(100, 4.0), ramp[::-1], np.zeros(100)])
    theta = theta + rng.normal(0, 0.3, len(theta))
    write_csv(tmp_path / "exp1.csv", columns(theta=theta))
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n')
    assert len(load_campaign(toml).experiments[0].t) == 700


# ---- bad rows: dropped up to 2 %, else an error ----


def test_a_few_bad_rows_are_dropped_with_a_note(tmp_path):
    lines = data_lines(columns(n=600))
    for line_index, cell in [(5, "abc"), (9, "n/a"), (30, "NaN"), (40, "inf"), (50, "")]:
        parts = lines[line_index].split(",")
        parts[2] = cell
        lines[line_index] = ",".join(parts)
    parts = lines[60].split(",")  # two bad cells in one row: one dropped row
    parts[0], parts[1] = "", "x"
    lines[60] = ",".join(parts)
    (tmp_path / "exp1.csv").write_text("\n".join(lines) + "\n")
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n')
    c = load_campaign(toml)
    e = c.experiments[0]
    assert e.rows == 600 and len(e.t) == len(e.theta) == len(e.y) == 594
    assert e.dropped == {"non-numeric": 2, "NaN": 1, "infinite": 1, "empty": 2}
    assert c.notes == ("exp1.csv: dropped 6 of 600 rows (2 non-numeric, 1 NaN, 1 infinite, 2 empty)",)
    assert np.all(np.isfinite(e.y)) and np.all(np.diff(e.t) > 0)


def test_a_short_row_counts_as_empty_cells(tmp_path):
    lines = data_lines(columns(n=600))
    lines[7] = lines[7].split(",")[0]  # only t_s
    (tmp_path / "exp1.csv").write_text("\n".join(lines) + "\n")
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n')
    c = load_campaign(toml)
    assert c.experiments[0].dropped == {"empty": 1}
    assert c.notes == ("exp1.csv: dropped 1 of 600 rows (1 empty)",)


def _spoil(lines, rows, cell, column=2):
    for r in rows:
        parts = lines[r].split(",")
        parts[column] = cell
        lines[r] = ",".join(parts)
    return lines


def test_too_many_non_numeric_cells_is_an_error(tmp_path):
    lines = _spoil(data_lines(columns(n=600)), range(16, 16 + 13), "abc")  # 13 > 2 % of 600
    msg = csv_error(tmp_path, lines)
    assert msg == (
        "exp1.csv: column torque_nmm: non-numeric value 'abc' at line 17 (13 of 600 rows bad; at most 2% are dropped)"
    )


def test_too_many_nans_is_an_error(tmp_path):
    lines = _spoil(data_lines(columns(n=600)), range(100, 600, 20), "nan", column=1)
    msg = csv_error(tmp_path, lines)
    assert msg == "exp1.csv: column theta_deg: NaN at line 101 (25 of 600 rows bad; at most 2% are dropped)"


def test_too_many_empty_cells_is_an_error(tmp_path):
    lines = _spoil(data_lines(columns(n=600)), range(300, 320), "", column=0)
    msg = csv_error(tmp_path, lines)
    assert msg == "exp1.csv: column t_s: empty cell at line 301 (20 of 600 rows bad; at most 2% are dropped)"


def test_too_many_infinite_values_is_an_error(tmp_path):
    lines = _spoil(data_lines(columns(n=600)), range(2, 600, 10), "-inf")
    msg = csv_error(tmp_path, lines)
    assert msg.startswith("exp1.csv: column torque_nmm: infinite value '-inf' at line 3 (60 of 600 rows bad")


# ---- CSV errors ----


def test_missing_column_names_the_drive_and_the_columns_found(tmp_path):
    cols = columns()
    cols["force"] = cols.pop("torque_nmm")
    msg = csv_error(tmp_path, data_lines(cols))
    assert msg == "exp1.csv: missing column 'torque_nmm' (drive 'bar'); columns found: t_s, theta_deg, force"


def test_missing_column_hints_at_the_other_drive(tmp_path):
    msg = csv_error(tmp_path, data_lines(columns(drive="tendon")), drive="bar")
    assert "missing column 'torque_nmm'" in msg and "is the drive 'tendon'?" in msg


def test_semicolon_separated_file_is_named(tmp_path):
    lines = [line.replace(",", ";") for line in data_lines(columns())]
    msg = csv_error(tmp_path, lines)
    assert "missing columns 't_s', 'theta_deg', 'torque_nmm'" in msg and "comma-separated" in msg


def test_duplicate_column_is_an_error(tmp_path):
    msg = csv_error(tmp_path, ["t_s,theta_deg,torque_nmm,t_s", "0,0,1,0"])
    assert msg == "exp1.csv: column 't_s' appears more than once (columns 1, 4)"


def test_time_must_increase(tmp_path):
    cols = columns()
    cols["t_s"][400] = cols["t_s"][399] - 0.005  # data row 401 → line 402
    msg = csv_error(tmp_path, data_lines(cols))
    assert msg == "exp1.csv: t_s is not increasing at line 402 (t = 3.985 s after 3.99 s)"


def test_repeated_time_is_not_increasing(tmp_path):
    cols = columns()
    cols["t_s"][10] = cols["t_s"][9]
    msg = csv_error(tmp_path, ["# header comment"] + data_lines(cols))
    assert msg.startswith("exp1.csv: t_s is not increasing at line 13 ")


def test_too_few_samples(tmp_path):
    cols = {k: v[:12] for k, v in columns(theta=[0, 10, 20, 30, 20, 10, 0, 10, 20, 10, 0, 5]).items()}
    msg = csv_error(tmp_path, data_lines(cols))
    assert msg == "exp1.csv: only 12 usable samples; at least 50 are needed"


def test_header_only_is_too_few_samples(tmp_path):
    msg = csv_error(tmp_path, ["t_s,theta_deg,torque_nmm"])
    assert "only 0 usable samples" in msg and "at least 50 are needed" in msg


def test_empty_file_is_too_few_samples(tmp_path):
    (tmp_path / "exp1.csv").write_text("")
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n')
    msg = error(toml)
    assert msg.startswith("exp1.csv: only 0 usable samples") and "at least 50 are needed" in msg


def test_no_reversal(tmp_path):
    cols = columns(theta=np.linspace(0, 90, 600))
    msg = csv_error(tmp_path, data_lines(cols))
    assert re.fullmatch(
        r"exp1\.csv: no reversal: the joint must move forward and back "
        r"\(range 0\.\d–89\.\d deg, monotonic; a reversal needs a return of at least 8\.9 deg\)",
        msg,
    )


def test_noisy_ramp_with_holds_is_no_reversal(tmp_path):
    rng = np.random.default_rng(7)
    theta = np.concatenate([np.zeros(200), np.linspace(0, 5, 300), np.full(300, 5.0)])
    theta = theta + rng.normal(0, 0.5, len(theta))  # camera noise larger than the 0.5° floor
    msg = csv_error(tmp_path, data_lines(columns(theta=theta)))
    assert msg.startswith("exp1.csv: no reversal")


def test_camera_glitches_do_not_make_a_reversal(tmp_path):
    theta = np.linspace(0, 90, 600)
    theta[[0, 200, 401]] = [40.0, 10.0, 95.0]  # single-frame tracking errors, one on the first row
    msg = csv_error(tmp_path, data_lines(columns(theta=theta)))
    assert msg.startswith("exp1.csv: no reversal")


def test_angle_range_below_one_degree(tmp_path):
    msg = csv_error(tmp_path, data_lines(columns(theta=triangle(top=0.6))))
    assert re.fullmatch(
        r"exp1\.csv: the joint angle spans only 0\.\d\d deg \(0\.0–0\.\d deg\); "
        r"it must move at least 1 deg",
        msg,
    )


def test_csv_that_is_not_utf8(tmp_path):
    (tmp_path / "exp1.csv").write_bytes(b"t_s,theta_deg,torque_nmm\n\xff\xfe,1,2\n")
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n')
    assert error(toml) == "exp1.csv: not a UTF-8 text file (byte 0xff on line 2)"


# ---- TOML errors ----


def test_missing_toml(tmp_path):
    toml = tmp_path / "campaign.toml"
    assert error(toml) == f"{toml}: file not found"


def test_toml_syntax_error(tmp_path):
    toml = tmp_path / "campaign.toml"
    toml.write_text("[design]\nstiffness_nmm_per_rad = \n")
    msg = error(toml)
    assert msg.startswith(f"{toml}: not valid TOML (") and "line 2" in msg


def test_missing_csv_file(tmp_path):
    write_csv(tmp_path / "exp1.csv", columns())
    toml = write_campaign(
        tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n[[experiment]]\nfile = "exp2.csv"\ndrive = "bar"\n'
    )
    assert error(toml).startswith(f"{toml}: experiment 2: file 'exp2.csv' not found")


def test_missing_design_table(tmp_path):
    toml = write_campaign(tmp_path, design="")
    msg = error(toml)
    assert msg.startswith(f"{toml}: missing [design] table") and "preload_deg" in msg


def test_missing_design_key(tmp_path):
    toml = write_campaign(tmp_path, design="[design]\nstiffness_nmm_per_rad = 5.2\npulley_radius_mm = 6\n")
    msg = error(toml)
    assert msg.startswith(f"{toml}: [design]: missing key 'preload_deg'")


def test_unknown_design_key_lists_the_known_keys(tmp_path):
    toml = write_campaign(tmp_path, design=DESIGN + "stiffness = 5\n")
    msg = error(toml, ParameterError)
    assert msg.startswith(f"{toml}: [design] stiffness = 5 is invalid: unknown key; known keys: ")
    assert "stiffness_nmm_per_rad, preload_deg, pulley_radius_mm" in msg


def test_unknown_experiment_key_lists_the_known_keys(tmp_path):
    write_csv(tmp_path / "exp1.csv", columns())
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\nnormal_load = 1.5\n')
    msg = error(toml, ParameterError)
    assert msg == (
        f"{toml}: experiment 1 (exp1.csv): normal_load = 1.5 is invalid: unknown key; "
        "known keys: file, drive, normal_load_n, routed, pulley_radius_mm"
    )


def test_unknown_top_level_key(tmp_path):
    toml = write_campaign(tmp_path, design=DESIGN + "\n[experiments]\nfile = 'a.csv'\n")
    assert error(toml) == f"{toml}: unknown key or table 'experiments'; known: [design], [[experiment]]"


@pytest.mark.parametrize(
    "line, expect",
    [
        ('stiffness_nmm_per_rad = "5.2"', "[design] stiffness_nmm_per_rad = '5.2' is invalid: must be a int or float"),
        ("stiffness_nmm_per_rad = 0", "[design] stiffness_nmm_per_rad = 0 is invalid: must be > 0"),
        ("pulley_radius_mm = -6", "[design] pulley_radius_mm = -6 is invalid: must be > 0"),
        ("preload_deg = nan", "design.preload_deg = nan is invalid: must be a finite number"),  # rjcad.io.untrusted
        ("preload_deg = true", "[design] preload_deg = True is invalid: must be a int or float"),
    ],
)
def test_bad_design_values(tmp_path, line, expect):
    key = line.split(" = ")[0]
    design = "\n".join(x if not x.startswith(key) else line for x in DESIGN.splitlines()) + "\n"
    toml = write_campaign(tmp_path, design=design)
    assert error(toml, ParameterError) == f"{toml}: {expect}"


@pytest.mark.parametrize(
    "extra, expect",
    [
        ("normal_load_n = -1", "normal_load_n = -1 is invalid: must be >= 0"),
        ("pulley_radius_mm = 0.0", "pulley_radius_mm = 0 is invalid: must be > 0"),
        ('routed = "yes"', "routed = 'yes' is invalid: must be true or false"),
        ("normal_load_n = '1.5'", "normal_load_n = '1.5' is invalid: must be a int or float"),
    ],
)
def test_bad_experiment_values(tmp_path, extra, expect):
    write_csv(tmp_path / "exp1.csv", columns(drive="tendon"))
    toml = write_campaign(tmp_path, f'[[experiment]]\nfile = "exp1.csv"\ndrive = "tendon"\n{extra}\n')
    assert error(toml, ParameterError) == f"{toml}: experiment 1 (exp1.csv): {expect}"


def test_unknown_drive(tmp_path):
    write_csv(tmp_path / "exp1.csv", columns())
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "motor"\n')
    assert error(toml, ParameterError) == (
        f"{toml}: experiment 1 (exp1.csv): drive = 'motor' is invalid: must be 'bar' or 'tendon'"
    )


def test_routed_bar_drive_is_an_error(tmp_path):
    write_csv(tmp_path / "exp1.csv", columns())
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\nrouted = true\n')
    msg = error(toml)
    assert msg.startswith(f"{toml}: experiment 1 (exp1.csv): routed = true is invalid with drive = 'bar'")


def test_missing_experiment_keys(tmp_path):
    write_csv(tmp_path / "exp1.csv", columns())
    toml = write_campaign(tmp_path, '[[experiment]]\ndrive = "bar"\n')
    assert error(toml).startswith(f"{toml}: experiment 1: missing key 'file'")
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\n')
    assert error(toml).startswith(f"{toml}: experiment 1 (exp1.csv): missing key 'drive'")


def test_no_experiments(tmp_path):
    toml = write_campaign(tmp_path, "")
    assert error(toml) == f"{toml}: no [[experiment]] tables; add one per CSV file"


def test_single_experiment_table_must_be_an_array(tmp_path):
    write_csv(tmp_path / "exp1.csv", columns())
    toml = write_campaign(tmp_path, '[experiment]\nfile = "exp1.csv"\ndrive = "bar"\n')
    assert "one [[experiment]] per CSV file" in error(toml)


def test_two_experiments_with_the_same_name(tmp_path):
    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        write_csv(tmp_path / d / "exp1.csv", columns())
    toml = write_campaign(
        tmp_path,
        '[[experiment]]\nfile = "a/exp1.csv"\ndrive = "bar"\n[[experiment]]\nfile = "b/exp1.csv"\ndrive = "bar"\n',
    )
    msg = error(toml)
    assert msg.startswith(f"{toml}: experiment 2 (b/exp1.csv): name 'exp1' is already used by experiment 1")


# ---- through the CLI: one stderr line, exit code 2 ----


def _cli_error(toml, capsys):
    with pytest.raises(SystemExit) as info:
        rjcad.cli.main(["identify", str(toml)])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    return err[0]


def test_cli_missing_csv_file(tmp_path, capsys):
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "gone.csv"\ndrive = "bar"\n')
    line = _cli_error(toml, capsys)
    assert "campaign.toml" in line and "gone.csv" in line and "not found" in line


def test_cli_missing_column(tmp_path, capsys):
    write_csv(tmp_path / "exp1.csv", columns(drive="tendon"))
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n')
    line = _cli_error(toml, capsys)
    assert "exp1.csv" in line and "missing column 'torque_nmm'" in line


def test_cli_no_reversal(tmp_path, capsys):
    write_csv(tmp_path / "exp1.csv", columns(theta=np.linspace(0, 90, 600)))
    toml = write_campaign(tmp_path, '[[experiment]]\nfile = "exp1.csv"\ndrive = "bar"\n')
    line = _cli_error(toml, capsys)
    assert "exp1.csv" in line and "no reversal" in line


def _bad_cells(value, every=10):
    cols = columns()
    lines = data_lines(cols)
    for i in range(1, len(lines), every):  # 10% of the rows: beyond what is dropped
        parts = lines[i].split(",")
        parts[2] = value
        lines[i] = ",".join(parts)
    return lines


@pytest.mark.parametrize(
    "case, expect",
    [
        ("non-numeric", "non-numeric value 'abc'"),
        ("nan", "NaN"),
        ("time", "t_s is not increasing"),
        ("few", "usable samples"),
        ("drive", "drive = 'motor' is invalid"),
    ],
)
def test_cli_every_bad_data_case_is_one_line_exit_2(tmp_path, capsys, case, expect):
    drive = "bar"
    if case == "non-numeric":
        lines = _bad_cells("abc")
    elif case == "nan":
        lines = _bad_cells("nan")
    elif case == "time":
        lines = data_lines(columns())
        lines[300], lines[301] = lines[301], lines[300]
    elif case == "few":
        lines = data_lines(columns())[:20]
    else:
        lines, drive = data_lines(columns()), "motor"
    (tmp_path / "exp1.csv").write_text("\n".join(lines) + "\n")
    toml = write_campaign(tmp_path, f'[[experiment]]\nfile = "exp1.csv"\ndrive = "{drive}"\n')
    out = tmp_path / "out.json"
    with pytest.raises(SystemExit) as info:
        rjcad.cli.main(["identify", str(toml), "--json", "--report", str(tmp_path / "rep")])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "exp1.csv" in err[0] and expect in err[0], err
    assert "Traceback" not in err[0]
    assert not out.exists() and not (tmp_path / "rep").exists()  # no partial output


def test_cli_reports_dropped_rows(tmp_path, capsys):
    from rjcad.identify.bench import write_campaign as bench

    bench(tmp_path / "c", ["coulomb_pin"], seed=2, experiments=[{"name": "A", "drive": "bar", "normal_load": 1.5}])
    csv = tmp_path / "c" / "A_bar_Fn1.5.csv"
    lines = csv.read_text().splitlines()
    for i in (100, 200, 1500):
        lines[i] = lines[i].rsplit(",", 1)[0] + ",NaN"
    lines[700] = lines[700].rsplit(",", 1)[0] + ",n/a"
    csv.write_text("\n".join(lines) + "\n")
    out = tmp_path / "r.json"
    with pytest.raises(SystemExit) as info:
        rjcad.cli.main(["identify", str(tmp_path / "c" / "campaign.toml"), "--json", str(out)])
    assert info.value.code == 0
    text = capsys.readouterr().out
    assert "dropped 4 of 3000 rows (1 non-numeric, 3 NaN)" in text
    import json

    js = json.loads(out.read_text())
    assert js["experiments"][0]["rows_dropped"] == {"non-numeric": 1, "NaN": 3}
    assert js["effects"] == ["coulomb_pin"]
