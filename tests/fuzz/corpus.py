"""The fuzz corpus: abusive inputs for every command, each with what must happen.

A ``Case`` is a command line run in its own directory (the runner forks a warm interpreter per case,
see runner.py). Its ``setup`` writes the inputs there. What every case must show (checked by
tests/test_fuzz_corpus.py):

* ``error``: exit code 2, stderr exactly one line starting ``rjcad: error: `` (at most MAX_LINE
  characters, naming one of ``mention``), and the case's directory exactly as it was before (names,
  bytes, modification times): nothing new, nothing half-written, an earlier run untouched;
* ``ok``: exit code 0 and nothing on stderr that looks like a traceback or a warning;
* ``either``: one of the two (the value may be legal), each with its own promise;
* ``checked``: ``rjcad check`` ran to a verdict (exit 0 or 1) with nothing on stderr;
* every case: no traceback, no warning, finished within its timeout, no process left behind;
  ``forbid`` never appears in its output; ``post`` (when given) checks the files it left.

Classes (the ``id`` prefix): ``num`` option values; ``toml``/``json`` damaged input files for every
command that reads one (printer and material profiles included); ``out`` output places that cannot be written; ``mesh``/``manifest`` for
``rjcad check``; ``sweep`` sweep files and bad designs; ``resume`` damaged results.csv; ``ident``
campaigns that name files outside their folder or give radians; ``long`` huge values; ``grammar`` the inputs
of docs/cli.md's grammar (a campaign's folder, ``--out`` on a file, the former spellings and their note line).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import random
import shutil
import struct
import subprocess
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

MAX_LINE = 500
BIG = "1" + "0" * 400  # an integer no float holds
STRICT = ("nan", "inf", "-inf", "1e400", "abc", "")  # never a legal value of a number option
LOOSE = ("0", "-1", "5e-324", "1e308")  # may be legal for some options: then the command must succeed


@dataclass
class Case:
    """One command line, its inputs and what must happen."""

    id: str
    argv: list[str]
    expect: str = "error"
    setup: Callable[[Path], None] = lambda d: None
    mention: tuple[str, ...] = ()
    forbid: tuple[str, ...] = ()
    read_only: bool = False  # the command obeys file modes although it runs as root
    fsize: int | None = None
    timeout: float = 60.0
    post: Callable[[Path, int], None] | None = None
    needs: str | None = None  # "mount": skipped where tmpfs cannot be mounted
    tags: dict = field(default_factory=dict)


@dataclass
class Shared:
    """Inputs several cases copy: a built joint (STL, manifest, its files), a small campaign, a sweep."""

    root: Path
    joint: Path  # directory of a built default joint (rjcad joint --no-png)
    finger_one: Path  # a one-joint finger template
    campaign: Path  # a small synthetic campaign (rjcad bench)
    sweep_file: Path  # a 6-design analytic sweep
    sweep_out: Path  # its finished output (results.csv)


# ------------------------------------------------------------------------------------------ helpers


def write(path: Path, data: bytes | str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
    return path


def copy_tree(src: Path, dst: Path) -> None:
    shutil.copytree(src, dst, dirs_exist_ok=True)


def garbage(n: int, seed: int) -> bytes:
    return random.Random(seed).randbytes(n)


def read_only(path: Path) -> None:
    """Mode 0555 (the case runs with ``read_only``, so that root obeys it)."""
    path.chmod(0o555)


def open_dir(path: Path) -> Path:
    path.mkdir(parents=True, exist_ok=True)
    path.chmod(0o777)
    return path


# ------------------------------------------------------------------------------- shared inputs

SWEEP_TOML = """[sweep]
mode = "grid"

[fixed]
preload_deg = 90
printer = "generic-0.4"

[params.stiffness_nmm_per_rad]
range = [4, 6]
steps = 3

[params.material]
values = ["absplus-p430", "pla"]
"""

FINGER_ONE = """material = "absplus-p430"
printer = "generic-0.4"

[defaults]
preload_deg = 90
rotation_deg = 90

[[joint]]
stiffness_nmm_per_rad = 5.2
link_length_mm = 44
"""


#: A printer and a material profile (docs/profiles.md) of the user's own.
PRINTER_PROFILE = """name = "a 0.6 mm printer"
nozzle_mm = 0.6
layer_mm = 0.3
bed_mm = [180, 180, 180]
soluble_support = false
"""
MATERIAL_PROFILE = """name = "a soft filament"
youngs_modulus_mpa = 1900
yield_mpa = 40
density_g_cm3 = 1.2
"""


def make_shared(root: Path, python: str, repo: Path) -> Shared:
    """Build the shared inputs with the real CLI (a joint, a campaign, a finished sweep)."""
    root.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, MPLBACKEND="Agg")
    write(root / "sweep.toml", SWEEP_TOML)
    write(root / "finger1.toml", FINGER_ONE)
    runs = [
        ["joint", "--out", str(root / "joint"), "--no-png"],
        ["bench", "--out", str(root / "campaign"), "--samples", "200"],
        ["sweep", str(root / "sweep.toml"), "--out", str(root / "sweep"), "--workers", "0"],
    ]
    procs = [
        subprocess.Popen(
            [python, "-m", "rjcad", *args], cwd=repo, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
        )
        for args in runs
    ]  # independent: side by side
    try:
        for args, proc in zip(runs, procs):
            _, err = proc.communicate(timeout=600)
            if proc.returncode:
                raise subprocess.CalledProcessError(proc.returncode, ["rjcad", *args], stderr=err)
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    for p in [root, *root.rglob("*")]:
        p.chmod(0o755 if p.is_dir() else 0o644)
    return Shared(root, root / "joint", root / "finger1.toml", root / "campaign", root / "sweep.toml", root / "sweep")


# ------------------------------------------------------------------------- 1. option values

NUMERIC = {
    "spring": (
        ["spring", "--stiffness", "5.2"],
        [
            "--stiffness",
            "--rotation",
            "--preload",
            "--safety-factor",
            "--min-gap",
            "--width-min",
            "--width-max",
            "--inner-radius-min",
            "--inner-radius-max",
            "--max-outer-radius",
            "--min-turns",
            "--min-cycles",
            "--backlash",
        ],
    ),
    "joint": (
        ["joint", "--out", "o", "--no-png"],
        [
            "--stiffness",
            "--rotation",
            "--preload",
            "--clearance",
            "--link-length",
            "--tendon-diameter",
            "--tendon-moment-arm",
            "--pin-radius",
            "--safety-factor",
        ],
    ),
    "check": (["check", "{joint}/joint.stl", "--manifest", "{joint}/joint.json"], ["--clearance", "--allowance"]),
    "simjoint": (
        ["simulate", "joint", "--rotation", "90"],
        [
            "--normal-load",
            "--stiffness",
            "--preload",
            "--mu-j",
            "--gamma-pos",
            "--gamma-neg",
            "--beta-pos",
            "--beta-neg",
            "--tendon-moment-arm",
            "--rotation",
        ],
    ),
    "simfinger": (["simulate", "finger"], ["--stroke", "--mu-t", "--gravity", "--max-tension"]),
    "simbearing": (["simulate", "joint", "--rotation", "90", "--friction", "bearing"], ["--mu", "--rotation"]),
    "simfingerbearing": (["simulate", "finger", "--friction", "bearing"], ["--mu"]),
    "design": (
        ["finger-design", "--target", "65,50,50", "--stroke", "25", "--out", "d"],
        ["--stroke", "--base-stiffness"],
    ),
    "bench": (["bench", "--out", "c", "--samples", "200"], ["--rotation"]),
    "view": (["view", "{joint}/joint.json", "--out", "v"], ["--stroke", "--mu-t"]),
}
INTEGER = {
    "spring": (["spring", "--stiffness", "5.2"], ["--springs", "--arms"]),
    "joint": (["joint", "--out", "o"], ["--arms"]),
    "check": (["check", "{joint}/joint.stl"], ["--bodies"]),
    "simfinger": (["simulate", "finger"], ["--steps"]),
    "view": (["view", "{joint}/joint.json", "--out", "v"], ["--steps"]),
    "bench": (["bench", "--out", "c"], ["--samples", "--seed"]),
    "life": (["life"], ["--sims"]),
    "sweep": (["sweep", "{sweep_file}", "--out", "o"], ["--workers"]),
}


def _fmt(argv, sh: Shared):
    return [a.format(joint=sh.joint, sweep_file=sh.sweep_file, campaign=sh.campaign) for a in argv]


def option_cases(sh: Shared) -> list[Case]:
    cases = []
    for cmd, (base, options) in NUMERIC.items():
        for opt in options:
            for i, v in enumerate(STRICT):
                cases.append(Case(f"num-{cmd}{opt}-{i}", _fmt(base, sh) + [f"{opt}={v}"], mention=(opt[2:],)))
            if cmd in ("spring", "simjoint"):
                for i, v in enumerate(LOOSE if cmd == "spring" else LOOSE[::3]):
                    cases.append(
                        Case(
                            f"num-{cmd}{opt}-loose{i}",
                            _fmt(base, sh) + [f"{opt}={v}"],
                            expect="either",
                            mention=(opt[2:],),
                        )
                    )
    for cmd, (base, options) in INTEGER.items():
        for opt in options:
            for i, v in enumerate(("abc", "1.5", "nan", "", BIG)):
                expect = "either" if (opt, v) == ("--seed", BIG) else "error"  # numpy takes any integer seed
                cases.append(Case(f"int-{cmd}{opt}-{i}", _fmt(base, sh) + [f"{opt}={v}"], expect, mention=(opt[2:],)))
    for i, t in enumerate(("abc", "nan,50,50", "1e400,50,50", "", "65,,50", "65;50", "-10,50,50", "inf")):
        cases.append(
            Case(
                f"num-design--target-{i}",
                ["finger-design", f"--target={t}", "--stroke", "25", "--out", "d"],
                mention=("target",),
            )
        )
    for i, n in enumerate(("torque_nmm=abc", "theta_deg=nan", "nosuchcolumn=0.1", "torque_nmm=-1", "=", "x")):
        cases.append(Case(f"num-bench--noise-{i}", ["bench", "--out", "c", f"--noise={n}"], mention=("noise",)))
    for i, p in enumerate(("mu_j_mm=abc", "mu_j_mm=nan", "nosuch=1", "mu_j_mm", "mu_j_mm=1e400", "=1")):
        cases.append(Case(f"num-bench--param-{i}", ["bench", "--out", "c", f"--param={p}"], mention=("param",)))
    for opt, v in (
        ("--material", "unobtainium"),
        ("--printer", "toaster"),
        ("--end", "glued"),
        ("--material", "x" * 100_000),
    ):
        for cmd in ("spring", "joint"):
            base = ["spring", "--stiffness", "5.2"] if cmd == "spring" else ["joint", "--out", "o"]
            cases.append(Case(f"num-{cmd}{opt}-{len(v)}", base + [f"{opt}={v}"], mention=(opt[2:],)))
    cases.append(Case("num-joint--layout", ["joint", "--out", "o", "--layout", "sideways"], mention=("layout",)))
    for v in ("0", "3", "-1"):  # spring arms: 1 or 2
        for cmd in ("spring", "joint"):
            base = ["spring", "--stiffness", "5.2"] if cmd == "spring" else ["joint", "--out", "o"]
            cases.append(Case(f"num-{cmd}--arms-{v}", base + ["--arms", v], mention=("arms",)))
    # two arms: the desktop layout only; the default wind-up (90° + 90°) has no two-arm spring that fits
    cases.append(
        Case(
            "num-joint--arms-stacked", ["joint", "--out", "o", "--arms", "2", "--layout", "stacked"], mention=("arms",)
        )
    )
    cases.append(Case("num-joint--arms-default", ["joint", "--out", "o", "--arms", "2"], mention=("arms",)))
    # the bearing model's loop (issue #36): its own options, the paper model's refused, a μ that locks the joint
    sim = ["simulate", "joint", "--rotation", "90"]
    for name, extra, words in (
        ("friction", ["--friction", "sliding"], "friction"),
        ("geometry", ["--friction", "bearing", "--geometry", "round"], "geometry"),
        ("geometry-alone", ["--geometry", "desktop"], "geometry"),
        ("mu-alone", ["--mu", "0.3"], "mu"),
        ("mu-j", ["--friction", "bearing", "--mu-j", "3"], "mu-j"),
        ("routed", ["--friction", "bearing", "--routed"], "routed"),
        ("range", ["--friction", "bearing", "--rotation", "91"], "rotation"),
        ("mu-big", ["--friction", "bearing", "--mu", "2.5"], "mu"),
        ("locks", ["--friction", "bearing", "--geometry", "desktop", "--drive", "tendon", "--mu", "1.5"], "mu"),
    ):
        cases.append(Case(f"num-simjoint-bearing-{name}", sim + extra, mention=(words,)))
    # the finger's bearing friction: its μ alone, a μ that locks joint 1, an engine that cannot carry it
    for name, extra, words in (
        ("mu-alone", ["--mu", "0.3"], "mu"),
        ("friction", ["--friction", "sliding"], "friction"),
        ("locks", [str(sh.joint / "joint.json"), "--friction", "bearing", "--mu", "1.5"], "mu"),  # the desktop joint
        ("mujoco", ["--friction", "bearing", "--engine", "mujoco"], "friction"),
        ("compare", ["--friction", "bearing", "--compare"], "friction"),
    ):
        cases.append(Case(f"num-simfinger-bearing-{name}", ["simulate", "finger", *extra], mention=(words,)))
    return cases


# ------------------------------------------------------------------ 2. damaged TOML and JSON files


@dataclass(frozen=True)
class TomlUser:
    """A command reading a TOML file: its command line ({f} = the file), a valid file, a number's line."""

    name: str
    argv: tuple[str, ...]
    valid: str
    line: str  # "key = value" in ``valid``, the number the damage replaces


def toml_users(sh: Shared) -> list[TomlUser]:
    campaign = (sh.campaign / "campaign.toml").read_text()
    finger = FINGER_ONE
    return [
        TomlUser(
            "spring", ("spring", "--config", "{f}"), "stiffness_nmm_per_rad = 5.2\n", "stiffness_nmm_per_rad = 5.2"
        ),
        TomlUser(
            "joint",
            ("joint", "--config", "{f}", "--out", "o", "--no-png"),
            "stiffness_nmm_per_rad = 5.2\n",
            "stiffness_nmm_per_rad = 5.2",
        ),
        TomlUser("finger", ("finger", "{f}", "--out", "o", "--no-png"), finger, "preload_deg = 90"),
        TomlUser("simfinger", ("simulate", "finger", "{f}", "--json"), finger, "preload_deg = 90"),
        TomlUser("sweep", ("sweep", "{f}", "--out", "o", "--workers", "0"), SWEEP_TOML, "preload_deg = 90"),
        TomlUser("identify", ("identify", "camp/campaign.toml", "--json"), campaign, "stiffness_nmm_per_rad = 5.2"),
        TomlUser("printer", ("spring", "--stiffness", "5.2", "--printer", "{f}"), PRINTER_PROFILE, "nozzle_mm = 0.6"),
        TomlUser("material", ("spring", "--stiffness", "5.2", "--material", "{f}"), MATERIAL_PROFILE, "yield_mpa = 40"),
        TomlUser("profile-show", ("profiles", "show", "{f}"), PRINTER_PROFILE, "nozzle_mm = 0.6"),
    ]


def toml_damages(valid: str, line: str) -> dict[str, bytes | str | None]:
    key = line.split("=")[0].strip()
    assert line in valid, line
    sub = lambda v: valid.replace(line, f"{key} = {v}", 1)  # noqa: E731
    head = valid.split("\n[", 1)
    return {
        "overflow": sub(BIG),
        "overflow-neg": sub("-" + BIG),
        "deep-tables": valid + "\ndeep = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n",
        "deep-arrays": valid + "\ndeep = " + "[" * 5000 + "]" * 5000 + "\n",
        "deep-arrays-head": "deep = " + "[" * 5000 + "]" * 5000 + "\n" + valid,
        "garbage": garbage(4096, 1),
        "utf16": valid.encode("utf-16"),
        "nul": valid[: len(valid) // 2] + "\x00" + valid[len(valid) // 2 :],
        "missing": None,
        "string": sub('"5.2"'),
        "bool": sub("true"),
        "nan": sub("nan"),
        "inf": sub("inf"),
        "neg-inf": sub("-inf"),
        "array": sub("[1, 2]"),
        "table": sub("{ a = 1 }"),
        "date": sub("1979-05-27"),
        "long-string": sub('"' + "x" * 200_000 + '"'),
        "unknown-key": "no_such_key_anywhere = 1\n" + valid,
        "syntax": valid + "\n= = =\n",
        "dup-key": head[0] + f"\n{line}\n{line}\n" + ("\n[" + head[1] if len(head) > 1 else ""),
        "huge": valid + ("# " + "x" * 98 + "\n") * 20_000,  # 2 MB of comments (the limit is 1 MB)
    }


def toml_cases(sh: Shared) -> list[Case]:
    cases = []
    for user in toml_users(sh):
        fname = "camp/campaign.toml" if user.name == "identify" else "in.toml"
        for kind, data in toml_damages(user.valid, user.line).items():

            def setup(d, data=data, user=user, fname=fname):
                if user.name == "identify":
                    copy_tree(sh.campaign, d / "camp")
                    (d / fname).unlink()
                if data is not None:
                    write(d / fname, data)

            argv = [a.replace("{f}", fname) for a in user.argv]
            expect = "error"
            key = user.line.split("=")[0].strip()
            cases.append(
                Case(
                    f"toml-{user.name}-{kind}",
                    argv,
                    expect,
                    setup,
                    mention=(Path(fname).name, key),
                    timeout=120 if kind == "huge" else 60,
                )
            )
        if user.name == "identify":
            cases.append(
                Case(
                    "toml-identify-directory",
                    list(user.argv),
                    setup=lambda d, fname=fname: (d / fname).mkdir(parents=True),
                    mention=("campaign.toml",),
                )
            )
        else:
            cases.append(
                Case(
                    f"toml-{user.name}-directory",
                    [a.replace("{f}", "adir") for a in user.argv],
                    setup=lambda d: (d / "adir").mkdir(),
                    mention=("adir",),
                )
            )
    return cases


def _manifest(sh: Shared) -> dict:
    return json.loads((sh.joint / "joint.json").read_text())


def manifest_damages(sh: Shared) -> dict[str, bytes | str | None]:
    def mut(fn):
        d = _manifest(sh)
        fn(d)
        return json.dumps(d, allow_nan=True)

    text = json.dumps(_manifest(sh))
    return {
        "list": json.dumps([_manifest(sh)]),
        "scalar": "42",
        "garbage": garbage(4096, 2),
        "utf16": text.encode("utf-16"),
        "nul": text[:100] + "\x00" + text[100:],
        "empty": "",
        "missing": None,
        "truncated": text[: len(text) // 2],
        "deep": "[" * 100_000 + "]" * 100_000,
        "deep-object": '{"a":' * 50_000 + "1" + "}" * 50_000,
        "huge-int": text.replace('"tendon_moment_arm_mm": 6.0', f'"tendon_moment_arm_mm": {BIG}', 1),
        "no-bodies": mut(lambda d: d.pop("bodies")),
        "bodies-string": mut(lambda d: d.__setitem__("bodies", "ground")),
        "bodies-empty": mut(lambda d: d.__setitem__("bodies", [])),
        "body-no-volume": mut(lambda d: d["bodies"][0].pop("volume_mm3")),
        "body-volume-string": mut(lambda d: d["bodies"][0].__setitem__("volume_mm3", "big")),
        "body-volume-nan": mut(lambda d: d["bodies"][0].__setitem__("volume_mm3", math.nan)),
        "body-volume-negative": mut(lambda d: d["bodies"][0].__setitem__("volume_mm3", -1.0)),
        "body-no-name": mut(lambda d: d["bodies"][0].pop("name")),
        "no-axis": mut(lambda d: [e.pop("axis_dir", None) for e in [d, *d.get("joints", [])]]),
        "zero-axis": mut(lambda d: [e.__setitem__("axis_dir", [0.0, 0.0, 0.0]) for e in [d, *d.get("joints", [])]]),
        "axis-short": mut(lambda d: d.__setitem__("axis_dir", [0.0, 1.0])),
        "axis-strings": mut(lambda d: d.__setitem__("axis_dir", ["0", "0", "1"])),
        "axis-point-nan": mut(lambda d: d.__setitem__("axis_point_mm", [math.nan, 0.0, 0.0])),
        "clearance-zero": mut(lambda d: d.__setitem__("clearance_mm", 0.0)),
        "clearance-nan": mut(lambda d: d.__setitem__("clearance_mm", math.nan)),
        "clearance-negative": mut(lambda d: d.__setitem__("clearance_mm", -1.0)),
        "clearance-inf": mut(lambda d: d.__setitem__("clearance_mm", math.inf)),
        "clearance-string": mut(lambda d: d.__setitem__("clearance_mm", "0.4")),
        "rotation-nan": mut(lambda d: d.__setitem__("rotation_deg", math.nan)),
        "rotation-huge": mut(lambda d: d.__setitem__("rotation_deg", 1e300)),
        "printer-unknown": mut(lambda d: d.__setitem__("printer", "toaster")),
        "moving-unknown": mut(lambda d: d.__setitem__("moving_body", "nobody")),
        "schema-future": mut(lambda d: d.__setitem__("schema_version", 99)),
        "stiffness-string": mut(lambda d: d.__setitem__("joint_stiffness_nmm_per_rad", "5.2")),
        "spring-null": mut(lambda d: d.__setitem__("spring", None)),
    }


def json_cases(sh: Shared) -> list[Case]:
    users = {
        "check": ["check", str(sh.joint / "joint.stl"), "--manifest", "m.json"],
        "simfinger": ["simulate", "finger", "m.json", "--json"],
        "paperfinger": ["paper-finger", "--out", "o", "--manifest", "m.json"],
        "urdf": ["urdf", "m.json", "--out", "o"],  # its meshes: the joint's 3MF beside it, as m.3mf
    }
    cases = []
    for name, argv in users.items():
        for kind, data in manifest_damages(sh).items():
            if name not in ("check", "urdf") and kind.startswith(("clearance", "axis-point", "moving", "printer")):
                continue  # fields only the mesh check (and the URDF) read
            # the physics does not read the bodies nor the axis: a manifest without them may still simulate
            expect = "either" if name != "check" and kind.startswith(("bod", "no-bodies", "no-axis")) else "error"
            if name == "urdf":  # the URDF reads the bodies and the axis, not the volumes, spring or printer
                expect = "either" if kind in ("body-no-volume", "spring-null", "printer-unknown") else "error"
            words = ("m.json", "manifest", *kind.split("-")[:2])
            cases.append(
                Case(
                    f"json-{name}-{kind}",
                    argv,
                    expect,
                    lambda d, data=data, name=name: _manifest_setup(sh, d, data, name),
                    mention=words,
                )
            )
    return cases


#: The damages a manifest's rebuild reads (rjcad.design.rebuild): ``simulate finger --friction bearing`` gets them.
REBUILT = ("huge-int", "clearance", "rotation", "printer", "schema", "stiffness", "spring-null", "missing", "list")


def bearing_cases(sh: Shared) -> list[Case]:
    """``simulate finger MANIFEST --friction bearing``: the joints rebuilt from a damaged manifest (the fields the
    rebuild reads; the rest are json_cases')."""
    argv = ["simulate", "finger", "m.json", "--friction", "bearing", "--json"]
    return [
        Case(
            f"json-bearing-{kind}",
            argv,
            "error",
            lambda d, data=data: _manifest_setup(sh, d, data, "bearing"),
            mention=("m.json", "manifest", *kind.split("-")[:2]),
            timeout=60,
        )
        for kind, data in manifest_damages(sh).items()
        if kind.startswith(REBUILT)
    ]


def _manifest_setup(sh: Shared, d: Path, data: bytes | str | None, user: str) -> None:
    """A damaged manifest as ``m.json`` (none: missing); for ``rjcad urdf``, the joint's meshes beside it."""
    if data is not None:
        write(d / "m.json", data)
    if user == "urdf":
        shutil.copyfile(sh.joint / "joint.3mf", d / "m.3mf")


# -------------------------------------------------------------------------- 3. output places


def writers(sh: Shared) -> dict[str, tuple[list[str], str]]:
    """Command lines that write, ``{o}`` the place: (argv, 'dir' when {o} is a directory, else 'file')."""
    return {
        "joint": (["joint", "--out", "{o}"], "dir"),
        "joint-nopng": (["joint", "--out", "{o}", "--no-png", "--stiffness", "8"], "dir"),
        "finger": (["finger", str(sh.finger_one), "--out", "{o}", "--no-png"], "dir"),
        "identify-json": (["identify", str(sh.campaign / "campaign.toml"), "--json", "{o}/r.json"], "file"),
        "identify-report": (["identify", str(sh.campaign / "campaign.toml"), "--report", "{o}"], "dir"),
        "sweep": (["sweep", str(sh.sweep_file), "--out", "{o}", "--workers", "0"], "dir"),
        "bench": (["bench", "--out", "{o}", "--samples", "200"], "dir"),
        "spring-plot": (["spring", "--stiffness", "5.2", "--plot", "{o}/s.png"], "file"),
        "simjoint-plot": (["simulate", "joint", "--rotation", "90", "--plot", "{o}/j.png"], "file"),
        "simfinger-plot": (["simulate", "finger", "--plot", "{o}/f.png"], "file"),
        "design": (["finger-design", "--target", "65,50,50", "--stroke", "25", "--out", "{o}"], "dir"),
        "design-file": (["finger-design", "--target", "65,50,50", "--stroke", "25", "--out", "{o}/f.toml"], "file"),
        "view": (["view", str(sh.joint / "joint.json"), "--out", "{o}"], "dir"),
        "paperfinger": (["paper-finger", "--out", "{o}"], "dir"),
        "life-plot": (["life", "--plot", "{o}/l.png"], "file"),
        "check-junit": (["check", str(sh.joint / "joint.stl"), "--junit", "{o}/r.xml"], "file"),
    }


SLOW_WRITERS = ("joint-nopng", "finger", "paperfinger", "identify-report")
#: Writers given in a former spelling (docs/cli.md): a note line on stderr before the usual.
FORMER_WRITERS = ("identify-json", "design-file")


def _earlier_run(d: Path) -> None:
    """An earlier run's files (the joint's) in ``d``."""
    d.mkdir(parents=True, exist_ok=True)
    for name in ("joint.stl", "joint.json", "results.csv", "r.json", "report.md", "f.toml", "finger.toml", "s.png"):
        write(d / name, f"earlier run: {name}\n")


def output_cases(sh: Shared) -> list[Case]:
    cases = []
    for name, (argv, _) in writers(sh).items():
        heavy = name in ("joint", "joint-nopng", "finger")
        big = "error" if heavy else "either"  # small outputs may fit in what is left
        if name == "check-junit":  # written, its verdict is the check's (exit 0 or 1)
            big = "either-checked"

        former = name in FORMER_WRITERS  # a former spelling: its note line comes first

        def mk(place, o, setup, expect="error", name=name, argv=argv, heavy=heavy, former=former, **kw):
            cases.append(
                Case(
                    f"out-{name}-{place}",
                    [a.replace("{o}", o) for a in argv],
                    expect,
                    setup,
                    mention=(o.split("/")[0],),
                    timeout=180 if heavy else 90,
                    tags={"note": "allowed"} if former else {},
                    **kw,
                )
            )

        mk("parent-is-file", "afile/sub", lambda d: write(d / "afile", "a regular file\n"))
        mk(
            "ro-earlier",
            "rodir",
            lambda d: (_earlier_run(open_dir(d / "rodir")), read_only(d / "rodir")),
            read_only=True,
        )
        if name not in SLOW_WRITERS:  # every place once for the slow ones is enough: they share the writer
            mk("ro-empty", "rodir", lambda d: read_only(open_dir(d / "rodir")), read_only=True)
            mk("ro-parent", "rodir/new", lambda d: read_only(open_dir(d / "rodir")), read_only=True)
        mk("fsize-earlier", "fsz", lambda d: _earlier_run(open_dir(d / "fsz")), big, fsize=20_000)
        mk("full-disk", "fulldisk", lambda d: _mount_small(d / "fulldisk"), big, needs="mount")
    return cases


def _mount_small(path: Path) -> None:
    """A 64 kB tmpfs at ``path`` holding an earlier run (unmounted by the test's teardown)."""
    path.mkdir(parents=True, exist_ok=True)
    subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=64k,mode=0777", "tmpfs", str(path)], check=True, capture_output=True
    )
    _earlier_run(path)


def can_mount(tmp: Path) -> bool:
    """Whether this process may mount a tmpfs (root outside a locked-down container)."""
    probe = tmp / "mount-probe"
    probe.mkdir(exist_ok=True)
    ok = (
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16k", "tmpfs", str(probe)], capture_output=True).returncode
        == 0
    )
    if ok:
        subprocess.run(["umount", str(probe)], capture_output=True)
    return ok


# ----------------------------------------------------------------------------- 4. rjcad check


def _binary_stl(n_claimed: int, triangles: int) -> bytes:
    body = struct.pack("<12fH", *([0.0] * 9 + [1.0, 0.0, 0.0]), 0) * triangles
    return b"\0" * 80 + struct.pack("<I", n_claimed) + body


def _box_with(kind: str) -> bytes:
    """A unit box as STL with a defect rjcad check must report without a warning on stderr."""
    import numpy as np
    import trimesh

    box = trimesh.creation.box((10, 10, 10))
    v, f = np.array(box.vertices), np.array(box.faces)
    if kind == "degenerate":
        f = np.vstack([f, [[f[0, 0], f[0, 0], f[0, 1]]]])
    elif kind == "duplicated":
        f = np.vstack([f, f[:3]])
    elif kind == "collinear":
        v = np.vstack([v, (v[f[0, 0]] + v[f[0, 1]]) / 2])
        f = np.vstack([f, [[f[0, 0], f[0, 1], len(v) - 1]]])
    elif kind == "nan":
        v[0] = np.nan
    mesh = trimesh.Trimesh(v, f, process=False)
    return trimesh.exchange.stl.export_stl(mesh)


def check_cases(sh: Shared) -> list[Case]:
    stl = (sh.joint / "joint.stl").read_bytes()
    meshes = {
        "missing": (None, "error"),
        "empty": (b"", "error"),
        "garbage": (garbage(20_000, 3), "error"),
        "truncated": (stl[: len(stl) // 2 + 7], "error"),
        "claims-a-billion": (_binary_stl(10**9, 3), "error"),
        "header-only": (_binary_stl(0, 0), "error"),
        "ascii-garbage": (b"solid x\nfacet normal nan nan nan\nouter loop\nvertex a b c\n", "error"),
        "degenerate": (_box_with("degenerate"), "checked"),
        "duplicated": (_box_with("duplicated"), "checked"),
        "collinear": (_box_with("collinear"), "checked"),
        "nan-vertex": (_box_with("nan"), "either-checked"),
    }
    cases = []
    for kind, (data, expect) in meshes.items():
        cases.append(
            Case(
                f"mesh-stl-{kind}",
                ["check", "m.stl"],
                expect,
                lambda d, data=data: data is not None and write(d / "m.stl", data),
                mention=("m.stl",),
            )
        )
    zbuf = io.BytesIO()
    with zipfile.ZipFile(zbuf, "w") as z:
        z.writestr("readme.txt", "no model here")
    for kind, data in {"garbage": garbage(5000, 4), "no-model": zbuf.getvalue(), "empty": b""}.items():
        cases.append(
            Case(
                f"mesh-3mf-{kind}",
                ["check", "m.3mf"],
                setup=lambda d, data=data: write(d / "m.3mf", data),
                mention=("m.3mf",),
            )
        )
    cases.append(Case("mesh-directory", ["check", "adir"], setup=lambda d: (d / "adir").mkdir(), mention=("adir",)))
    cases.append(
        Case(
            "mesh-unknown-suffix", ["check", "m.xyz"], setup=lambda d: write(d / "m.xyz", "1 2 3\n"), mention=("m.xyz",)
        )
    )
    cases.append(
        Case("mesh-printer", ["check", str(sh.joint / "joint.stl"), "--printer", "toaster"], mention=("printer",))
    )
    return cases


# ------------------------------------------------------------------------------ 5. sweep files


def sweep_damages() -> dict[str, tuple[str, tuple[str, ...]]]:
    """Damaged sweep files: (text, words of which the error line names one)."""
    s = SWEEP_TOML
    lhs = 'mode = "lhs"\nsamples = 4'
    mat = 'values = ["absplus-p430", "pla"]'
    return {
        "string-in-values": (s.replace('["absplus-p430", "pla"]', '["absplus-p430", 3]'), ("material",)),
        "number-string-in-values": (
            s.replace(mat, mat + '\n[params.rotation_deg]\nvalues = [60, "ninety", 120]'),
            ("rotation_deg",),
        ),
        "string-in-fixed": (s.replace("preload_deg = 90", 'preload_deg = "ninety"'), ("preload_deg",)),
        "bool-in-fixed": (s.replace("preload_deg = 90", "preload_deg = true"), ("preload_deg",)),
        "nan-in-fixed": (s.replace("preload_deg = 90", "preload_deg = nan"), ("preload_deg",)),
        "range-one": (s.replace("range = [4, 6]", "range = [4]"), ("range",)),
        "range-three": (s.replace("range = [4, 6]", "range = [4, 5, 6]"), ("range",)),
        "range-strings": (s.replace("range = [4, 6]", 'range = ["4", "6"]'), ("range",)),
        "range-reversed": (s.replace("range = [4, 6]", "range = [6, 4]"), ("range",)),
        "range-nan": (s.replace("range = [4, 6]", "range = [nan, 6]"), ("range",)),
        "range-not-list": (s.replace("range = [4, 6]", "range = 4"), ("range",)),
        "steps-string": (s.replace("steps = 3", 'steps = "3"'), ("steps",)),
        "steps-float": (s.replace("steps = 3", "steps = 2.5"), ("steps",)),
        "steps-zero": (s.replace("steps = 3", "steps = 0"), ("steps",)),
        "steps-huge": (s.replace("steps = 3", "steps = 1000000000"), ("steps", "designs", "points")),
        "steps-overflow": (s.replace("steps = 3", f"steps = {BIG}"), ("steps", "s.toml")),
        "samples-string": (s.replace('mode = "grid"', 'mode = "lhs"\nsamples = "ten"'), ("samples",)),
        "seed-string": (s.replace('mode = "grid"', lhs + '\nseed = "one"'), ("seed",)),
        "samples-float": (s.replace('mode = "grid"', 'mode = "lhs"\nsamples = 4.5'), ("samples",)),
        "values-not-list": (s.replace(mat, 'values = "pla"'), ("values", "material")),
        "values-empty": (s.replace(mat, "values = []"), ("values", "material")),
        "lhs-values-empty": (s.replace('mode = "grid"', lhs).replace(mat, "values = []"), ("values", "material")),
        "values-and-range": (s.replace("steps = 3", "steps = 3\nvalues = [4]"), ("values", "range", "stiffness")),
        "params-not-table": (s.split("[params.")[0] + "params = 3\n", ("params", "s.toml")),
        "mode-unknown": (s.replace('"grid"', '"random"'), ("mode",)),
        "mode-number": (s.replace('"grid"', "3"), ("mode",)),
        "sweep-not-table": ('sweep = "grid"\n' + s.split("\n", 2)[2], ("sweep", "s.toml")),
        "unknown-param": (s.replace("preload_deg = 90", "preload_deg = 90\nwarp_factor = 9"), ("warp_factor",)),
        "printer-number": (s.replace('printer = "generic-0.4"', "printer = 4"), ("printer",)),
    }


def _rows(out: Path) -> list[dict]:
    with open(out / "results.csv", newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _row_error(col: str):
    def post(d: Path, code: int) -> None:
        rows = _rows(d / "o")
        assert len(rows) == 6 and len({r["id"] for r in rows}) == 6, rows
        bad = [r for r in rows if r["status"] != "ok"]
        assert bad, f"a design with an invalid {col} came out ok"
        assert all(r.get("error") for r in bad), bad

    return post


def sweep_cases(sh: Shared) -> list[Case]:
    cases = [
        Case(
            f"sweep-{k}",
            ["sweep", "s.toml", "--out", "o", "--workers", "0"],
            setup=lambda d, t=t: write(d / "s.toml", t),
            mention=("s.toml",) + words,
        )
        for k, (t, words) in sweep_damages().items()
    ]
    bad_design = {  # a bad design is a row with its error, not a bad file
        "clearance-negative": ("clearance_mm", "clearance_mm = -3", []),
        "clearance-negative-build": ("clearance_mm", "clearance_mm = -3", ["--build"]),
        "link-short-build": ("link_length_mm", "link_length_mm = 5", ["--build"]),
        "rotation-zero": ("rotation_deg", "rotation_deg = 0", []),
        "safety-below-one": ("safety_factor", "safety_factor = 0.5", []),
        "material-unknown": ("material", "", []),
    }
    for name, (col, line, extra) in bad_design.items():
        text = (
            SWEEP_TOML.replace("preload_deg = 90", f"preload_deg = 90\n{line}")
            if line
            else SWEEP_TOML.replace('"pla"]', '"cheese"]')
        )
        cases.append(
            Case(
                f"sweep-design-{name}",
                ["sweep", "s.toml", "--out", "o", "--workers", "0", *extra],
                "ok",
                lambda d, t=text: write(d / "s.toml", t),
                post=_row_error(col),
                timeout=180,
            )
        )
    return cases


# ---------------------------------------------------------------------------- 6. --resume


def resume_damages(csv_text: str) -> dict[str, bytes | str]:
    lines = csv_text.splitlines(keepends=True)
    head, rows = lines[0], lines[1:]
    body = "".join(rows)
    last = rows[-1]
    return {
        "cut-mid-row": head + "".join(rows[:-1]) + last[: len(last) // 2],
        "cut-in-id": head + "".join(rows[:-1]) + last[:5],
        "cut-after-id": head + "".join(rows[:-1]) + last[:13],
        "garbage-lines": head + rows[0] + "%%%% not a row %%%%\n" + "".join(rows[1:]) + ",,,,\n",
        "garbage-tail": head + body + garbage(300, 5).decode("latin-1"),
        "no-id-column": head.replace("id,", "ident,", 1) + body,
        "nul-bytes": head + rows[0] + "\x00\x00" + "".join(rows[1:]),
        "utf16": (head + body).encode("utf-16"),
        "duplicated": head + body + body,
        "header-only": head,
        "empty": "",
        "binary": garbage(2000, 6),
        "rows-shuffled-extra-column": head.rstrip("\n") + ",extra\n" + body,
    }


def _exactly_once(sh: Shared):
    want = {r["id"] for r in _rows(sh.sweep_out)}

    def post(d: Path, code: int) -> None:
        if code != 0:
            return
        ids = [r["id"] for r in _rows(d / "o")]
        assert sorted(ids) == sorted(want), f"{len(ids)} rows, {len(set(ids))} designs, want each of {len(want)} once"

    return post


def resume_cases(sh: Shared) -> list[Case]:
    text = (sh.sweep_out / "results.csv").read_text(encoding="utf-8")
    cases = []
    for kind, data in resume_damages(text).items():

        def setup(d, data=data):
            copy_tree(sh.sweep_out, d / "o")
            write(d / "o" / "results.csv", data)

        cases.append(
            Case(
                f"resume-{kind}",
                ["sweep", str(sh.sweep_file), "--out", "o", "--workers", "0", "--resume"],
                "either",
                setup,
                mention=("results.csv",),
                post=_exactly_once(sh),
            )
        )
    return cases


# ---------------------------------------------------------------------------- 7. identify


def identify_cases(sh: Shared) -> list[Case]:
    cases = []

    def campaign(d: Path, edit: Callable[[str], str] | None = None, files: dict | None = None) -> None:
        copy_tree(sh.campaign, d / "camp")
        if edit:
            p = d / "camp" / "campaign.toml"
            p.write_text(edit(p.read_text()))
        for name, data in (files or {}).items():
            write(d / "camp" / name, data)

    first = "A_bar_Fn1.5.csv"
    outside = {
        "etc-passwd": lambda t: t.replace(f'"{first}"', '"/etc/passwd"'),
        "dotdot": lambda t: t.replace(f'"{first}"', '"../../../../../../etc/passwd"'),
        "dotdot-sibling": lambda t: t.replace(f'"{first}"', '"../outside.csv"'),
        "proc": lambda t: t.replace(f'"{first}"', '"/proc/self/environ"'),
        "dev-zero": lambda t: t.replace(f'"{first}"', '"/dev/zero"'),
    }
    for kind, edit in outside.items():

        def setup(d, edit=edit):
            campaign(d, edit)
            shutil.copy(sh.campaign / first, d / "outside.csv")

        cases.append(
            Case(
                f"ident-{kind}",
                ["identify", "camp/campaign.toml", "--json"],
                setup=setup,
                mention=("campaign.toml", "allow-outside", "outside"),
                forbid=("root:", "PATH="),
                timeout=30,
            )
        )

    def symlink_out(d):
        campaign(d)
        (d / "camp" / first).unlink()
        (d / "camp" / first).symlink_to("/etc/passwd")

    cases.append(
        Case(
            "ident-symlink-out",
            ["identify", "camp/campaign.toml", "--json"],
            setup=symlink_out,
            mention=(first, "allow-outside", "outside"),
            forbid=("root:",),
        )
    )

    def radians(d):
        campaign(d)
        for p in (d / "camp").glob("*.csv"):
            rows = list(csv.reader(p.open()))
            i = rows[0].index("theta_deg")
            for r in rows[1:]:
                r[i] = f"{math.radians(float(r[i])):.6f}"
            buf = io.StringIO()
            csv.writer(buf, lineterminator="\n").writerows(rows)
            p.write_text(buf.getvalue())

    cases.append(
        Case(
            "ident-radians",
            ["identify", "camp/campaign.toml", "--json"],
            setup=radians,
            mention=("theta_deg", "radian"),
        )
    )
    csv_damage = {
        "not-csv": garbage(3000, 7),
        "empty": "",
        "header-only": "t_s,theta_deg,torque_nmm\n",
        "missing-column": "t_s,theta_deg\n0,1\n0.1,2\n",
        "text-values": "t_s,theta_deg,torque_nmm\n0,one,2\n0.1,two,3\n",
        "nan-values": "t_s,theta_deg,torque_nmm\n" + "".join(f"{i / 10},nan,{i}\n" for i in range(300)),
        "inf-values": "t_s,theta_deg,torque_nmm\n" + "".join(f"{i / 10},{i},inf\n" for i in range(300)),
        "time-backwards": "t_s,theta_deg,torque_nmm\n" + "".join(f"{-i / 10},{i % 90},{i % 7}\n" for i in range(300)),
        "utf16": "t_s,theta_deg,torque_nmm\n0,1,2\n".encode("utf-16"),
        "huge-number": "t_s,theta_deg,torque_nmm\n" + "".join(f"{i / 10},{BIG},{i}\n" for i in range(300)),
        "ragged": "t_s,theta_deg,torque_nmm\n0,1\n0.1,2,3,4\n",
    }
    for kind, data in csv_damage.items():
        cases.append(
            Case(
                f"ident-csv-{kind}",
                ["identify", "camp/campaign.toml", "--json"],
                setup=lambda d, data=data: campaign(d, files={first: data}),
                mention=(first,),
            )
        )
    for kind, edit in {
        "no-file-key": lambda t: t.replace(f'file = "{first}"\n', "", 1),
        "file-number": lambda t: t.replace(f'"{first}"', "3", 1),
        "no-experiments": lambda t: t.split("[[experiment]]")[0],
        "drive-unknown": lambda t: t.replace('drive = "bar"', 'drive = "rope"', 1),
        "missing-data-file": lambda t: t.replace(f'"{first}"', '"nope.csv"', 1),
    }.items():
        cases.append(
            Case(
                f"ident-toml-{kind}",
                ["identify", "camp/campaign.toml", "--json"],
                setup=lambda d, edit=edit: campaign(d, edit),
                mention=("campaign.toml", "nope.csv", "experiment", "drive", "file"),
            )
        )
    return cases + _joint_manifest_cases(sh, campaign)


def _joint_manifest_cases(sh: Shared, campaign: Callable) -> list[Case]:
    """``[design] joint``: the joint's manifest a campaign names (its bearing's geometry), outside the folder, not
    a file or not a string, and damaged like any manifest (what the rebuild does not read may be damaged)."""

    def naming(value: str) -> Callable[[str], str]:
        return lambda t: t.replace("[design]\n", f"[design]\njoint = {value}\n", 1)

    cases = []
    for kind, value in {
        "etc-passwd": '"/etc/passwd"',
        "dotdot": '"../../../../../../etc/passwd"',
        "dev-zero": '"/dev/zero"',
        "folder": '"."',
        "number": "3",
        "empty": '""',
        "missing": '"nope.json"',
    }.items():
        cases.append(
            Case(
                f"ident-joint-{kind}",
                ["identify", "camp/campaign.toml", "--json"],
                setup=lambda d, value=value: campaign(d, naming(value)),
                mention=("campaign.toml", "joint"),
                forbid=("root:",),
                timeout=30,
            )
        )
    unread = ("no-bodies", "bodies", "body", "no-axis", "zero-axis", "axis", "moving")
    for kind, data in manifest_damages(sh).items():
        files = {} if data is None else {"joint.json": data}
        cases.append(
            Case(
                f"ident-joint-manifest-{kind}",
                ["identify", "camp/campaign.toml", "--json"],
                "either" if kind.startswith(unread) else "error",
                setup=lambda d, files=files: campaign(d, naming('"joint.json"'), files),
                mention=("joint", "campaign.toml", *kind.split("-")[:2]),
                timeout=60,
            )
        )
    return cases


# ------------------------------------------------------------------------------- 8. long values


def long_cases(sh: Shared) -> list[Case]:
    huge = "x" * 2_000_000
    return [
        Case(
            "long-config-string",
            ["spring", "--config", "c.toml"],
            setup=lambda d: write(d / "c.toml", f'material = "{huge}"\nstiffness_nmm_per_rad = 5.2\n'),
            mention=("material", "c.toml"),
        ),
        Case(
            "long-sweep-value",
            ["sweep", "s.toml", "--out", "o", "--workers", "0"],
            setup=lambda d: write(d / "s.toml", SWEEP_TOML.replace('"pla"', f'"{huge}"')),
            expect="either",
            mention=("material", "s.toml"),
        ),
        Case(
            "long-cli-material", ["spring", "--stiffness", "5.2", "--material", huge[:100_000]], mention=("material",)
        ),
        Case(
            "long-key",
            ["spring", "--config", "c.toml"],
            setup=lambda d: write(d / "c.toml", f"{'k' * 500_000} = 1\nstiffness_nmm_per_rad = 5.2\n"),
            mention=("c.toml",),
        ),
        Case("long-path", ["check", "a" * 5000 + ".stl"], mention=("aaaa", "file name")),
    ]


# ------------------------------------------------------------------------ 9. the grammar (docs/cli.md)


def grammar_cases(sh: Shared) -> list[Case]:
    """The input kinds the grammar added: a campaign named by its folder, ``--out`` on an existing file (the
    former ``--out FILE`` commands), and every former spelling, which still works with its note line."""
    cases = []
    design = ["finger-design", "--target", "65,50,50", "--stroke", "25"]
    view = ["view", str(sh.joint / "joint.json")]

    def folder(d: Path, toml: bytes | str | None) -> None:
        copy_tree(sh.campaign, d / "camp")
        (d / "camp" / "campaign.toml").unlink()
        if toml is not None:
            write(d / "camp" / "campaign.toml", toml)

    for kind, toml in {
        "missing": None,
        "garbage": garbage(2048, 9),
        "empty": "",
        "utf16": (sh.campaign / "campaign.toml").read_text().encode("utf-16"),
        "syntax": "[[experiment]\nfile = \n",
        "no-experiments": "[design]\nstiffness_nmm_per_rad = 5.2\n",
    }.items():
        cases.append(
            Case(
                f"grammar-ident-dir-{kind}",
                ["identify", "camp", "--json"],
                setup=lambda d, toml=toml: folder(d, toml),
                mention=("camp", "campaign.toml"),
            )
        )
    cases.append(
        Case(
            "grammar-ident-dir-toml-is-dir",
            ["identify", "camp", "--json"],
            setup=lambda d: (folder(d, None), (d / "camp" / "campaign.toml").mkdir()),
            mention=("camp", "campaign.toml"),
        )
    )
    cases.append(Case("grammar-ident-dir-ok", ["identify", str(sh.campaign), "--json"], "ok", timeout=120))
    cases.append(
        Case("grammar-ident-json-before-campaign", ["identify", "--json", str(sh.campaign)], "ok", timeout=120)
    )
    for name, argv in (("view", view), ("design", design)):
        cases.append(
            Case(
                f"grammar-out-{name}-existing-file",
                [*argv, "--out", "afile"],
                setup=lambda d: write(d / "afile", "a file the user keeps\n"),
                mention=("afile",),
            )
        )
        cases.append(
            Case(
                f"grammar-out-{name}-existing-file-in-path",
                [*argv, "--out", "afile/sub"],
                setup=lambda d: write(d / "afile", "a file the user keeps\n"),
                mention=("afile",),
            )
        )
    cases.append(  # the manifest itself as --out (a typo the former file form would have overwritten)
        Case(
            "grammar-out-view-is-the-manifest",
            ["view", "m.json", "--out", "m.json"],
            setup=lambda d: shutil.copyfile(sh.joint / "joint.json", d / "m.json"),
            mention=("m.json",),
        )
    )
    cases.append(  # a folder named like a page: a folder, the page inside
        Case(
            "grammar-out-view-folder-named-html",
            [*view, "--out", "page.html"],
            "ok",
            setup=lambda d: (d / "page.html").mkdir(),
            post=lambda d, code: _exists(d / "page.html" / "joint.html"),
        )
    )
    former = [  # (id, argv, what it writes)
        ("simjoint-pulley-radius", ["simulate", "joint", "--rotation", "90", "--pulley-radius", "5"], None),
        ("view-out-file", [*view, "--out", "page.html"], "page.html"),
        ("design-out-file", [*design, "--out", "f.toml"], "f.toml"),
        ("identify-json-file", ["identify", str(sh.campaign), "--json", "r.json"], "r.json"),
    ]
    for kind, argv, made in former:
        cases.append(
            Case(
                f"grammar-former-{kind}",
                argv,
                "ok",
                tags={"note": "required"},
                post=(lambda d, code, made=made: _exists(d / made)) if made else None,
                timeout=120,
            )
        )
    for i, v in enumerate(STRICT):  # a bad value by the former name: named by it
        cases.append(
            Case(
                f"grammar-former-pulley-radius-{i}",
                ["simulate", "joint", "--rotation", "90", f"--pulley-radius={v}"],
                mention=("pulley-radius",),
                tags={"note": "allowed"},
            )
        )
    cases.append(
        Case(
            "grammar-former-and-new-together",
            ["simulate", "joint", "--rotation", "90", "--pulley-radius", "5", "--tendon-moment-arm", "5"],
            mention=("pulley-radius", "tendon-moment-arm"),
        )
    )
    return cases


# ------------------------------------------------------------------- 10. special files, links, locales


def _special(path: Path, kind: str) -> None:
    """Make ``path`` a FIFO, a link to a device, a socket or a link to itself (a loop)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        path.symlink_to("/dev/zero")
    elif kind == "socket":
        import socket

        with socket.socket(socket.AF_UNIX) as sock:
            sock.bind(str(path))
    else:  # a loop
        path.symlink_to(path.name)


#: What an input may be instead of a regular file.
SPECIAL_KINDS = ("fifo", "device", "socket", "loop")


def input_roles(sh: Shared) -> dict[str, tuple[list[str], str, Callable[[Path], None]]]:
    """Every input a command reads, ``{f}`` the file made special: (argv, the file's path, setup of the rest)."""

    def camp(d: Path) -> None:
        copy_tree(sh.campaign, d / "camp")

    def camp_csv(d: Path) -> None:
        camp(d)
        first = sorted((d / "camp").glob("*.csv"))[0]
        first.rename(d / "camp" / "data.moved")
        (d / "camp" / "name.txt").write_text(first.name)

    def earlier(d: Path) -> None:
        copy_tree(sh.sweep_out, d / "o")

    def manifest_with(suffix: str):
        def setup(d: Path) -> None:
            shutil.copyfile(sh.joint / "joint.json", d / "m.json")
            if suffix != ".3mf":
                shutil.copyfile(sh.joint / "joint.3mf", d / "m.3mf")

        return setup

    none = lambda d: None  # noqa: E731
    return {
        "config": (["spring", "--config", "{f}"], "in.toml", none),
        "joint-config": (["joint", "--config", "{f}", "--out", "o", "--no-png"], "in.toml", none),
        "template": (["finger", "{f}", "--out", "o", "--no-png"], "in.toml", none),
        "simfinger": (["simulate", "finger", "{f}", "--json"], "in.toml", none),
        "sweep-file": (["sweep", "{f}", "--out", "o", "--workers", "0"], "in.toml", none),
        "printer": (["spring", "--stiffness", "5.2", "--printer", "{f}"], "p.toml", none),
        "material": (["spring", "--stiffness", "5.2", "--material", "{f}"], "m.toml", none),
        "profile-show": (["profiles", "show", "{f}"], "p.toml", none),
        "campaign": (["identify", "{f}", "--json"], "camp/campaign.toml", lambda d: (camp(d), (d / "camp" / "campaign.toml").unlink())),
        "mesh-stl": (["check", "{f}"], "in.stl", none),
        "mesh-3mf": (["check", "{f}"], "in.3mf", none),
        "check-manifest": (["check", str(sh.joint / "joint.stl"), "--manifest", "{f}"], "m.json", none),
        "manifest-sim": (["simulate", "finger", "{f}", "--json"], "m.json", none),
        "manifest-urdf": (["urdf", "{f}", "--out", "o"], "m.json", none),
        "manifest-view": (["view", "{f}", "--out", "o"], "m.json", none),
        "beside-glb": (["view", "m.json", "--out", "o"], "m.glb", manifest_with(".glb")),
        "beside-3mf": (["mjcf", "m.json", "--out", "o"], "m.3mf", manifest_with(".3mf")),
        "mjcf-xml": (["simulate", "finger", "--engine", "mujoco", "{f}"], "in.xml", none),
        "bench-source": (["bench", "--finger", "--source", "{f}", "--out", "o", "--samples", "200"], "in.toml", none),
        "identified": (["mjcf", "m.json", "--identified", "{f}", "--out", "o"], "id.json", manifest_with(".json")),
        "resume-csv": (["sweep", str(sh.sweep_file), "--out", "o", "--workers", "0", "--resume"], "o/results.csv", lambda d: (earlier(d), (d / "o" / "results.csv").unlink())),
        "resume-log": (["sweep", str(sh.sweep_file), "--out", "o", "--workers", "0", "--resume"], "o/results.partial.jsonl", earlier),
    }  # fmt: skip


def special_input_cases(sh: Shared) -> list[Case]:
    """Every input as a FIFO, a device, a socket or a link loop: refused in one line, before it is read (a FIFO
    would block a reader for ever)."""
    cases = []
    for role, (argv, path, setup) in input_roles(sh).items():
        for kind in SPECIAL_KINDS:

            def mk(d, setup=setup, path=path, kind=kind):
                setup(d)
                _special(d / path, kind)

            cases.append(
                Case(
                    f"special-{role}-{kind}",
                    [a.replace("{f}", path) for a in argv],
                    "error",
                    mk,
                    mention=(Path(path).name,),
                    timeout=30,
                )
            )
    return cases


#: Writers of one file, and where ``{o}`` puts it.
FILE_WRITERS = ("spring-plot", "simjoint-plot", "simfinger-plot", "life-plot", "check-junit")
#: Writers of a set, and one member the place holds already.
SET_MEMBERS = {"sweep": "results.csv", "bench": "campaign.toml", "design": "finger.toml", "view": "joint.html"}


def special_output_cases(sh: Shared) -> list[Case]:
    """An output that is a link (to a file outside, or dangling), a FIFO or a socket: never written through, never
    replaced (one line naming it; the outside file unchanged); a legal long name (up to 255 bytes) written."""
    cases = []
    places = {
        "link-outside": lambda f: (write(f.parent.parent / "outside.txt", "not rjcad's\n"), f.symlink_to("../outside.txt")),
        "link-dangling": lambda f: f.symlink_to("../nowhere.txt"),
        "fifo": lambda f: os.mkfifo(f),
        "socket": lambda f: _special(f, "socket"),
    }  # fmt: skip
    all_writers = writers(sh)
    # (writer, its command line, the file the place is made at): a single file's, or a set's member
    targets = [(n, all_writers[n][0], all_writers[n][0][-1].replace("{o}", "o")) for n in FILE_WRITERS]
    targets += [(n, all_writers[n][0], f"o/{member}") for n, member in SET_MEMBERS.items()]
    for name, argv, target in targets:
        for place, make in places.items():

            def setup(d, make=make, target=target):
                open_dir(d / "o")
                make(d / target)

            cases.append(
                Case(
                    f"special-out-{name}-{place}",
                    [a.replace("{o}", "o") for a in argv],
                    "error",
                    setup,
                    mention=(Path(target).name,),
                    timeout=90,
                )
            )
    for name in FILE_WRITERS:
        argv = all_writers[name][0]
        stem, suffix = Path(argv[-1]).stem, Path(argv[-1]).suffix
        for length in (245, 255):  # the whole name, suffix included: up to the longest legal one
            long_name = "n" * (length - len(suffix)) + suffix
            cases.append(
                Case(
                    f"special-out-{name}-name{length}",
                    [a.replace("{o}", "o").replace(stem + suffix, long_name) for a in argv],
                    "checked" if name == "check-junit" else "ok",
                    lambda d: open_dir(d / "o"),
                    timeout=90,
                    post=lambda d, code, long_name=long_name: _only(d / "o", {long_name}),
                )
            )
    return cases


def _only(folder: Path, names: set[str]) -> None:
    """``folder`` holds exactly ``names`` (no temporary file left beside them)."""
    have = {p.name for p in folder.iterdir()}
    assert have == names, f"{folder.name} holds {sorted(have)}, not {sorted(names)}"


def _parts_3mf(sh: Shared, first: str | None, last: str | None) -> bytes:
    """The joint's 3MF with its first part's firstid/lastid set to ``first``/``last`` (None: removed)."""
    src = zipfile.ZipFile(sh.joint / "joint.3mf")
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as out:
        for info in src.infolist():
            data = src.read(info.filename)
            if info.filename == "Metadata/Slic3r_PE_model.config":
                text = data.decode()
                head, rest = text.split("<volume ", 1)
                attrs, tail = rest.split(">", 1)
                kept = " ".join(a for a in attrs.split() if not a.startswith(("firstid=", "lastid=")))
                new = [kept]
                new += [f'firstid="{first}"'] if first is not None else []
                new += [f'lastid="{last}"'] if last is not None else []
                data = (head + "<volume " + " ".join(new) + ">" + tail).encode()
            out.writestr(info.filename, data)
    return buf.getvalue()


def _bomb_3mf(members: int, inflated: int) -> bytes:
    """A zip of ``members`` members, the first of ``inflated`` zero bytes (a zip bomb when large)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as out:
        with out.open("3D/3dmodel.model", "w", force_zip64=True) as f:
            block = bytes(1 << 20)
            for _ in range(inflated >> 20):
                f.write(block)
        for k in range(1, members):
            out.writestr(f"m/{k}", b"")
    return buf.getvalue()


def container_cases(sh: Shared) -> list[Case]:
    """3MF parts with broken ids, a zip bomb, too many members; JSON lines nested deep; a manifest's body named
    with a path; the designs of a sweep whose values are one number spelt three ways."""
    cases = []
    ids = {
        "text": ("a", "b"),
        "float": ("0.5", "9.5"),
        "missing-first": (None, "5"),
        "missing-last": ("0", None),
        "reversed": ("9", "3"),
        "negative": ("-4", "3"),
        "past-end": ("0", "99999999"),
    }
    for kind, (first, last) in ids.items():
        cases.append(
            Case(
                f"container-3mf-ids-{kind}",
                ["check", "in.3mf"],
                "error",
                lambda d, first=first, last=last: write(d / "in.3mf", _parts_3mf(sh, first, last)),
                mention=("in.3mf",),
            )
        )
    for kind, (members, inflated) in {"bomb": (1, 300 << 20), "members": (12_000, 0)}.items():
        cases.append(
            Case(
                f"container-3mf-{kind}",
                ["check", "in.3mf"],
                "error",
                lambda d, m=members, i=inflated: write(d / "in.3mf", _bomb_3mf(m, i)),
                mention=("in.3mf",),
                timeout=20,
            )
        )
    for kind, name in {"slash": "a/b", "dotdot": "..", "backslash": "a\\b", "hidden": ".x"}.items():

        def setup(d, name=name):
            man = json.loads((sh.joint / "joint.json").read_text())
            man["bodies"][0]["name"] = name
            if man.get("moving_body") and man["moving_body"] == man["bodies"][0].get("name"):
                man["moving_body"] = name
            write(d / "m.json", json.dumps(man))
            shutil.copyfile(sh.joint / "joint.3mf", d / "m.3mf")

        cases.append(
            Case(
                f"container-mjcf-body-{kind}",
                ["mjcf", "m.json", "--out", "o"],
                "error",
                setup,
                mention=("m.json", "name"),
            )
        )

    def bad_index(d: Path) -> None:
        src = zipfile.ZipFile(sh.joint / "joint.3mf")
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as out:
            for info in src.infolist():
                data = src.read(info.filename)
                if info.filename.endswith(".model"):
                    data = data.replace(b'<triangle v1="', b'<triangle v1="99999999" x1="', 1)
                out.writestr(info.filename, data)
        write(d / "in.3mf", buf.getvalue())

    cases.append(Case("container-3mf-index-out-of-range", ["check", "in.3mf"], "error", bad_index, mention=("in.3mf",)))

    def beside_outside(d: Path, suffix: str) -> None:
        shutil.copyfile(sh.joint / "joint.json", open_dir(d / "built") / "m.json")
        shutil.copyfile(sh.joint / ("joint.3mf" if suffix == ".3mf" else "joint.json"), d / f"elsewhere{suffix}")
        (d / "built" / f"m{suffix}").symlink_to(f"../elsewhere{suffix}")

    for suffix, argv in (
        (".glb", ["view", "built/m.json", "--out", "o"]),
        (".3mf", ["mjcf", "built/m.json", "--out", "o"]),
    ):
        cases.append(
            Case(
                f"container-beside{suffix.replace('.', '-')}-outside",
                argv,
                "error",
                lambda d, suffix=suffix: beside_outside(d, suffix),
                mention=(f"m{suffix}", "outside"),
            )
        )

    def huge_glb(d: Path) -> None:
        shutil.copyfile(sh.joint / "joint.json", d / "m.json")
        with (d / "m.glb").open("wb") as f:
            f.truncate(3 << 29)  # 1.5 GB, sparse: refused by its size, before it is read

    cases.append(
        Case(
            "container-view-huge-glb",
            ["view", "m.json", "--out", "o"],
            "error",
            huge_glb,
            mention=("m.glb",),
            timeout=10,
        )
    )

    def deep_log(d: Path) -> None:
        copy_tree(sh.sweep_out, d / "o")
        write(d / "o" / "results.partial.jsonl", "[" * 200_000 + "]" * 200_000 + "\n")

    cases.append(
        Case(
            "container-resume-deep-line",
            ["sweep", str(sh.sweep_file), "--out", "o", "--workers", "0", "--resume"],
            "either",
            deep_log,
            mention=("results",),
            post=_exactly_once(sh),
        )
    )
    spelt = SWEEP_TOML.replace("preload_deg = 90\n", "").replace(
        "[params.material]", "[params.preload_deg]\nvalues = [90, 90.0, 90.00]\n\n[params.material]"
    )
    assert spelt != SWEEP_TOML
    cases.append(
        Case(
            "container-sweep-one-number-three-ways",
            ["sweep", "s.toml", "--out", "o", "--workers", "0"],
            "ok",
            lambda d: write(d / "s.toml", spelt),
            post=lambda d, code: _row_count(d / "o" / "results.csv", _row_count_of(sh)),
        )
    )
    return cases


def _row_count_of(sh: Shared) -> int:
    with (sh.sweep_out / "results.csv").open(newline="") as f:
        return len(list(csv.DictReader(f)))


def _row_count(path: Path, n: int) -> None:
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == n, f"{len(rows)} rows for {n} designs (one number spelt three ways is one design)"


#: Commands whose output holds rjcad's symbols (→, °, θ, σ, ·), run on a terminal in ISO-8859-1 and in ASCII.
LOCALE_COMMANDS = {
    "simfinger": ["simulate", "finger"],
    "simjoint": ["simulate", "joint", "--rotation", "90"],
    "life": ["life"],
    "spring": ["spring", "--stiffness", "5.2"],
    "check": ["check", "{joint}/joint.stl", "--manifest", "{joint}/joint.json"],
    "identify": ["identify", "{campaign}/campaign.toml"],
}


def locale_cases(sh: Shared) -> list[Case]:
    """Every command that prints symbols, on streams that cannot encode them: exit 0 (1 for a check's verdict),
    no traceback, ASCII stand-ins."""
    cases = [
        Case(
            "locale-finger-latin-1",
            ["finger", str(sh.finger_one), "--out", "o", "--no-png"],
            "ok",
            timeout=180,
            tags={"encoding": "latin-1"},
            post=lambda d, code: _exists(d / "o" / "finger.json"),
        )
    ]
    for name, argv in LOCALE_COMMANDS.items():
        # ASCII: click writes UTF-8 on a plain-ASCII stream itself (it takes it for a misconfigured locale), so
        # the two light commands stand for the rest there
        for enc in ("latin-1", "ascii") if name in ("spring", "simfinger") else ("latin-1",):
            line = [a.replace("{joint}", str(sh.joint)).replace("{campaign}", str(sh.campaign)) for a in argv]
            cases.append(
                Case(
                    f"locale-{name}-{enc}",
                    line,
                    "checked" if name == "check" else "ok",
                    timeout=120,
                    tags={"encoding": enc},
                )
            )
    return cases


# ------------------------------------------------------------------------ objects (simulate finger --object)

#: Malformed ``--object`` specs (rjcad.physics.objects.parse_object): each is one error line naming --object.
BAD_OBJECTS = {
    "empty": "",
    "no-kind": "diameter=20,x=30,y=25",
    "unknown-kind": "sphere:diameter=20,x=30,y=25",
    "kind-only": "cylinder:",
    "no-equals": "cylinder:diameter,x=30,y=25",
    "unknown-key": "cylinder:diameter=20,x=30,y=25,z=3",
    "duplicate-key": "cylinder:diameter=20,x=30,y=25,x=31",
    "fixed-free": "cylinder:diameter=20,x=30,y=25,fixed,free",
    "free-no-mass": "cylinder:diameter=20,x=30,y=25,free",
    "mass-fixed": "cylinder:diameter=20,x=30,y=25,mass=5",
    "nan": "cylinder:diameter=nan,x=30,y=25",
    "inf": "box:w=inf,h=10,x=30,y=25",
    "huge": "cylinder:diameter=1e300,x=30,y=25",
    "big-int": f"cylinder:diameter=20,x={BIG},y=25",
    "negative": "box:w=-10,h=10,x=30,y=25",
    "zero": "cylinder:diameter=0,x=30,y=25",
    "mu-huge": "cylinder:diameter=20,x=30,y=25,mu=1e9",
    "angle-huge": "box:w=10,h=10,x=30,y=25,angle=1e20",
    "cylinder-angle": "cylinder:diameter=20,x=30,y=25,angle=10",
    "text": "cylinder:diameter=abc,x=30,y=25",
    "long": "cylinder:" + "x=1," * 50_000,
    "overlap": "cylinder:diameter=20,x=30,y=0",
}
#: Damaged ``[[object]]`` tables in a template (after a valid one-joint finger).
BAD_OBJECT_TABLES = {
    "unknown-key": 'kind = "cylinder"\ndiameter_mm = 20\nx_mm = 30\ny_mm = 25\nz_mm = 1',
    "no-kind": "diameter_mm = 20\nx_mm = 30\ny_mm = 25",
    "bad-kind": 'kind = "cone"\ndiameter_mm = 20\nx_mm = 30\ny_mm = 25',
    "string-number": 'kind = "cylinder"\ndiameter_mm = "20"\nx_mm = 30\ny_mm = 25',
    "free-text": 'kind = "box"\nw_mm = 20\nh_mm = 20\nx_mm = 30\ny_mm = 25\nfree = "yes"',
    "nan": 'kind = "cylinder"\ndiameter_mm = nan\nx_mm = 30\ny_mm = 25',
    "missing": 'kind = "box"\nw_mm = 20\nx_mm = 30\ny_mm = 25',
}
OBJECT_FINGER = 'material = "absplus-p430"\n[[joint]]\nstiffness_nmm_per_rad = 5.2\nlink_length_mm = 44\n'


def object_cases(sh: Shared) -> list[Case]:
    """``simulate finger --object`` with malformed specs, and templates with damaged ``[[object]]`` tables."""
    cases = [
        Case(f"obj-spec-{kind}", ["simulate", "finger", "--object", spec], mention=("object",))
        for kind, spec in BAD_OBJECTS.items()
    ]
    cases.append(Case("obj-spec-max-tension-nan", ["simulate", "finger", "--object", "cylinder:diameter=20,x=30,y=25",
                                                   "--max-tension", "nan"], mention=("max-tension",)))  # fmt: skip
    for kind, table in BAD_OBJECT_TABLES.items():

        def setup(d: Path, table: str = table) -> None:
            write(d / "t.toml", OBJECT_FINGER + "\n[[object]]\n" + table + "\n")

        cases.append(
            Case(f"obj-toml-{kind}", ["simulate", "finger", "t.toml"], setup=setup, mention=("t.toml", "object"))
        )
    return cases


def _exists(path: Path) -> None:
    assert path.is_file(), f"{path.name} was not written"


PARSE_CLASSES = ("num", "int", "obj")


def parse_only(case: Case) -> bool:
    """A case that tests only an option's value: it stops at a usage error (or, where the value may be legal, runs
    a command that writes no file: spring, simulate), and it has no input file, no output place, no file mode,
    size limit or mount, nothing to check afterwards. tests/test_fuzz_corpus.py runs these in its own process (the
    promises are the same); every other case runs as a process of its own."""
    cls = case.id.split("-")[0]
    return (
        (cls in PARSE_CLASSES or case.id == "long-cli-material")
        and (case.expect == "error" or (case.expect == "either" and case.argv[0] in ("spring", "simulate")))
        and not (case.read_only or case.fsize or case.needs or case.post)
    )


def all_cases(sh: Shared) -> list[Case]:
    cases = (
        option_cases(sh)
        + toml_cases(sh)
        + json_cases(sh)
        + bearing_cases(sh)
        + output_cases(sh)
        + check_cases(sh)
        + sweep_cases(sh)
        + resume_cases(sh)
        + identify_cases(sh)
        + long_cases(sh)
        + grammar_cases(sh)
        + special_input_cases(sh)
        + special_output_cases(sh)
        + container_cases(sh)
        + locale_cases(sh)
        + object_cases(sh)
    )
    ids = [c.id for c in cases]
    dup = {i for i in ids if ids.count(i) > 1}
    assert not dup, dup
    return cases
