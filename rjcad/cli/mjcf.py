"""``rjcad mjcf``: the MJCF of a built finger (one STL per body beside it); helpers for ``--engine mujoco``."""

from __future__ import annotations

from pathlib import Path

import click

from rjcad.errors import ParameterError, RjcadError, optional_import

GRAVITY_HELP = (
    "Gravity relative to the finger: horizontal-palm-down (default), horizontal-palm-up, "
    "vertical-tip-down, vertical-tip-up, lying-as-printed, off, or the angle from the finger's axis "
    "towards the palm [deg]."
)


def build_files(manifest_path: str, xml_name: str, gravity: str, identified: str | None, pull: str) -> dict:
    """The MJCF (named ``xml_name``) and its body STLs for the manifest at ``manifest_path``, in memory."""
    from rjcad.io.manifest import Manifest
    from rjcad.io.untrusted import read_json
    from rjcad.mjcf.export import check_identified, gravity_of, mesh_sources, mjcf_files, read_meshes

    man = Manifest.read(manifest_path)
    from rjcad.mjcf.export import check_manifest

    check_manifest(man, Path(manifest_path).name)
    ident = check_identified(read_json(identified), man, identified) if identified else None
    grav = gravity_of(gravity)
    meshes = read_meshes(mesh_sources(manifest_path, man))
    files = mjcf_files(man, meshes, xml_name, manifest_path, gravity=grav, identified=ident)
    if pull == "path":
        from rjcad.mjcf.spec import GROOVE_TENDON, PATH_TENDON

        xml = files[xml_name]
        assert isinstance(xml, str)  # the model is text; its meshes are bytes
        files[xml_name] = xml.replace(f'tendon="{GROOVE_TENDON}"', f'tendon="{PATH_TENDON}"')
    return files


@click.command()
@click.argument("manifest", type=click.Path(dir_okay=False))
@click.option(
    "--out",
    "out_path",
    type=click.Path(dir_okay=False),
    default="finger.xml",
    show_default=True,
    help="The MJCF to write; one STL per body is written beside it (<stem>_<body>.stl).",
)
@click.option(
    "--identified",
    type=click.Path(dir_okay=False),
    help="An `rjcad identify` result of this finger: its pin friction (frictionloss), stiffness, preload.",
)
@click.option("--gravity", default="horizontal-palm-down", show_default=True, help=GRAVITY_HELP)
@click.option(
    "--pull",
    type=click.Choice(["groove", "path"]),
    default="groove",
    show_default=True,
    help="What the `pull` actuator acts on: the fixed tendon of rjcad's model (constant moment arms) or "
    "the spatial tendon through the built path.",
)
def mjcf(manifest, out_path, identified, gravity, pull):
    """Write the MuJoCo model (MJCF, SI units) of a finger built by `rjcad finger` (its manifest FINGER.json and,
    beside it, its per-body STLs or its 3MF)."""
    from rjcad.io.outputs import write_set

    out = Path(out_path)
    if out.suffix.lower() != ".xml":
        raise ParameterError("--out", out_path, "must name an .xml file")
    files = build_files(manifest, out.name, gravity, identified, pull)
    write_set(out.parent if str(out.parent) else ".", files)
    n = len([f for f in files if f.endswith(".stl")])
    click.echo(f"MJCF written to {out} (and {n} body STLs beside it)")


def mujoco_model(source: str | None, gravity: str | None = None):
    """A loaded MuJoCo model for ``rjcad simulate finger --engine mujoco``: an MJCF (.xml, as it is), a finger
    manifest (.json: exported in memory from it and its meshes), or a template (.toml; default: the paper's):
    capsule links, no gravity unless ``gravity`` is given."""
    from rjcad.mjcf.simulate import load

    if source is not None and Path(source).suffix.lower() == ".xml":
        mujoco = optional_import("mujoco", "mujoco")

        if not Path(source).is_file():
            raise RjcadError(f"{source}: file not found")
        try:
            return mujoco.MjModel.from_xml_path(source)
        except ValueError as e:
            raise RjcadError(f"{source}: MuJoCo cannot load it: {str(e).splitlines()[0]}") from None
    if source is not None and Path(source).suffix.lower() == ".json":
        files = build_files(source, "finger.xml", gravity or "off", None, "groove")
        return load(files.pop("finger.xml"), dict(files))
    from rjcad.mjcf.export import gravity_of
    from rjcad.mjcf.model import spec_from_model
    from rjcad.mjcf.spec import to_xml
    from rjcad.physics.finger_sources import load_finger_model

    spec = spec_from_model(load_finger_model(source), gravity=gravity_of(gravity or "off"))
    return load(to_xml(spec))
