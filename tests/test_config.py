"""rjcad.io.config: TOML files checked key by key, and atomic writes that never leave a half file behind."""

import json
import os
import stat

import pytest

from rjcad.errors import ParameterError, RjcadError
from rjcad.io.config import check_key, load_toml, write_atomic, write_json

ALLOWED = {"stiffness_nmm_per_rad": (int, float), "material": str}


def test_load_toml_reads_known_keys(tmp_path):
    f = tmp_path / "j.toml"
    f.write_text('stiffness_nmm_per_rad = 5\nmaterial = "pla"\n')
    assert load_toml(f, ALLOWED) == {"stiffness_nmm_per_rad": 5, "material": "pla"}


@pytest.mark.parametrize(
    "text, parameter, words",
    [
        ("stifness = 5\n", "j.toml: stifness", "unknown key; known keys: stiffness_nmm_per_rad, material"),
        ('stiffness_nmm_per_rad = "5"\n', "j.toml: stiffness_nmm_per_rad", "must be a int or float"),
        ("stiffness_nmm_per_rad = true\n", "j.toml: stiffness_nmm_per_rad", "must be a int or float"),
        ("material = 3\n", "j.toml: material", "must be a str"),
    ],
)
def test_load_toml_names_the_bad_key(tmp_path, text, parameter, words):
    f = tmp_path / "j.toml"
    f.write_text(text)
    with pytest.raises(ParameterError) as e:
        load_toml(f, ALLOWED)
    assert e.value.parameter == parameter and e.value.limit == words


def test_load_toml_missing_or_broken_file_is_one_error(tmp_path):
    with pytest.raises(RjcadError, match="file not found"):
        load_toml(tmp_path / "nope.toml", ALLOWED)
    (tmp_path / "bad.toml").write_text("stiffness_nmm_per_rad = \n")
    with pytest.raises(RjcadError, match="not valid TOML"):
        load_toml(tmp_path / "bad.toml", ALLOWED)
    (tmp_path / "latin.toml").write_bytes(b'material = "\xe9"\n')
    with pytest.raises(RjcadError, match=r"latin\.toml: not a UTF-8 text file \(byte 0xe9 on line 1\)"):
        load_toml(tmp_path / "latin.toml", ALLOWED)


def test_check_key_returns_the_value():
    assert check_key("", "material", "pla", ALLOWED) == "pla"
    assert check_key("joint[2].", "stiffness_nmm_per_rad", 5.5, ALLOWED) == 5.5
    with pytest.raises(ParameterError) as e:
        check_key("joint[2].", "bogus", 1, ALLOWED)
    assert e.value.parameter == "joint[2].bogus"


def test_write_atomic_writes_text_and_bytes_with_umask_permissions(tmp_path):
    p = write_atomic(tmp_path / "sub" / "a.txt", "héllo\n")
    assert p.read_bytes() == "héllo\n".encode()
    write_atomic(p, b"\x00\x01")
    assert p.read_bytes() == b"\x00\x01"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~umask
    assert [q.name for q in p.parent.iterdir()] == ["a.txt"]


def test_write_atomic_failure_keeps_the_old_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    p = tmp_path / "a.json"
    p.write_text("old\n")

    def broken_replace(src, dst):
        raise OSError("disk on fire")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(RjcadError, match=r"a\.json: cannot write: disk on fire"):  # one error line, no traceback
        write_atomic(p, "new\n")
    assert p.read_text() == "old\n"
    assert [q.name for q in tmp_path.iterdir()] == ["a.json"]


def test_write_json_is_indented_and_ends_with_a_newline(tmp_path):
    p = write_json(tmp_path / "m.json", {"b": 1, "a": [1.5]})
    assert p.read_text() == json.dumps({"b": 1, "a": [1.5]}, indent=2) + "\n"
    assert list(json.loads(p.read_text())) == ["b", "a"]  # key order kept
