"""``rjcad mjcf``: the MJCF folder of a built finger (model, scene, meshes); helpers for ``--engine mujoco``."""

from __future__ import annotations

from pathlib import Path

import click

from rjcad.cli.options import OutDir, allow_outside_option
from rjcad.errors import RjcadError

GRAVITY_HELP = (
    "Gravity relative to the finger: horizontal-palm-down (default), horizontal-palm-up, "
    "vertical-tip-down, vertical-tip-up, lying-as-printed, off, or the angle from the finger's axis "
    "towards the palm [deg]. The MJCF turns the finger's base so that this points down."
)


def build_files(
    manifest_path: str, xml_name: str, gravity: str, identified: str | None, pull: str, allow_outside: bool = False
) -> dict:
    """The MJCF folder (the model ``xml_name``, scene.xml, meshes/<body>.stl) for the manifest at ``manifest_path``,
    in memory."""
    from rjcad.io.manifest import Manifest
    from rjcad.io.untrusted import read_json
    from rjcad.mjcf.export import check_identified, check_manifest, gravity_of, mesh_sources, mjcf_files, read_meshes

    man = Manifest.read(manifest_path)
    check_manifest(man, Path(manifest_path).name)
    ident = check_identified(read_json(identified), man, identified) if identified else None
    grav = gravity_of(gravity)
    meshes = read_meshes(mesh_sources(manifest_path, man, allow_outside))
    return mjcf_files(man, meshes, xml_name, manifest_path, gravity=grav, identified=ident, pull=pull)


def out_folder(manifest: str, out_path: str | None) -> tuple[Path, str]:
    """Where ``rjcad mjcf`` writes: (folder, model file name). ``--out DIR``; an ``.xml`` file (the former form)
    names the model in its folder, with the deprecation note; default: ``mjcf/`` beside the manifest."""
    from rjcad.cli.options import out_file

    stem = Path(manifest).stem
    if out_path is None:
        return Path(manifest).parent / "mjcf", f"{stem}.xml"
    folder, name = out_file(out_path, (".xml",), f"{stem}.xml")
    return Path(folder), name


@click.command()
@click.argument("manifest", type=click.Path(dir_okay=False))
@click.option(
    "--out",
    "out_path",
    type=OutDir(legacy=(".xml",)),
    default=None,
    help="The folder to write: <manifest stem>.xml (the model), scene.xml (the model over a floor, with lights) "
    "and meshes/<body>.stl. Default: mjcf/ beside the manifest.",
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
@click.option(
    "--object",
    "objects",
    multiple=True,
    metavar="SPEC",
    help="An object to grasp, e.g. cylinder:diameter=40,x=20,y=25,mu=0.5 or box:w=10,h=60,x=-6,y=40 "
    "(mm, deg; add free,mass=G for a free one), repeatable: written as a body with its geom, and each link "
    "gets contact pads from its outline.",
)
@allow_outside_option
def mjcf(manifest, out_path, identified, gravity, pull, objects, allow_outside):
    """Write the MuJoCo model (MJCF, SI units) of a finger built by `rjcad finger` (its manifest FINGER.json and,
    beside it, its 3MF): a folder with the model, scene.xml and the body meshes."""
    from rjcad.io.outputs import check_writable, write_set
    from rjcad.mjcf.spec import GROOVE_TENDON, PATH_TENDON

    folder, xml_name = out_folder(manifest, out_path)
    check_writable(folder)
    files = build_files(
        manifest, xml_name, gravity, identified, PATH_TENDON if pull == "path" else GROOVE_TENDON, allow_outside
    )
    if objects:
        files[xml_name] = with_objects(str(files[xml_name]), manifest, objects)
    write_set(folder, files)
    n = len([f for f in files if f.endswith(".stl")])
    click.echo(f"MJCF written to {folder / xml_name} (open {folder / 'scene.xml'}; {n} body meshes in meshes/)")
    echo_sag_of_manifest(manifest, gravity)


def with_objects(xml: str, manifest: str, specs: tuple[str, ...]) -> str:
    """The MJCF text ``xml`` of the finger ``manifest`` with the objects of the ``--object`` specs and the links'
    contact pads (rjcad.mjcf.grasp.add_grasp; outlines: the manifest's, measured on the solids, else the
    template's pads from its link lengths)."""
    from rjcad.io.manifest import Manifest
    from rjcad.mjcf.grasp import add_grasp
    from rjcad.physics.finger_sources import model_from_manifest
    from rjcad.physics.grasp_run import grasp_outlines_of
    from rjcad.physics.objects import parse_object

    objects = [parse_object(s) for s in specs]
    man = Manifest.read(manifest).to_json()
    return add_grasp(xml, objects, grasp_outlines_of(man, model_from_manifest(man)))


def echo_sag_of_manifest(manifest, gravity: str) -> None:
    """The one-line note (stderr) when the finger's springs cannot hold it straight against gravity ``gravity``
    (rjcad's statics on the manifest ``manifest``, a path or a ``Manifest``)."""
    from rjcad.io.manifest import Manifest
    from rjcad.mjcf.export import gravity_of
    from rjcad.mjcf.sag import rjcad_rest_pose, sag_note

    man = manifest if isinstance(manifest, Manifest) else Manifest.read(manifest)
    note = sag_note(rjcad_rest_pose(man, gravity_of(gravity)), f"--gravity {gravity}", "rjcad's statics")
    if note:
        click.echo(note, err=True)


def mujoco_model(source: str | None, gravity: tuple[float, float, float] | None = None):
    """A loaded MuJoCo model for ``rjcad simulate finger --engine mujoco``: an MJCF (.xml, as it is), a finger
    manifest (.json: exported in memory from it and its meshes), or a template (.toml; default: the paper's):
    capsule links; ``gravity`` [m/s², finger frame] (None: off) for the latter two."""
    from rjcad.mjcf.simulate import load

    if source is not None and Path(source).suffix.lower() == ".xml":
        from rjcad.io.untrusted import read_bytes
        from rjcad.mjcf.simulate import quiet_mujoco

        mujoco = quiet_mujoco()
        read_bytes(source, "text")  # a regular file within the size cap (a FIFO would block MuJoCo's reader)
        try:
            return mujoco.MjModel.from_xml_path(source)
        except ValueError as e:
            raise RjcadError(f"{source}: MuJoCo cannot load it: {str(e).splitlines()[0]}") from None
    grav = gravity if gravity is not None else (0.0, 0.0, 0.0)
    if source is not None and Path(source).suffix.lower() == ".json":
        from rjcad.io.manifest import Manifest
        from rjcad.mjcf.export import check_manifest, mesh_sources, mjcf_files, read_meshes

        man = Manifest.read(source)
        check_manifest(man, Path(source).name)
        files = mjcf_files(man, read_meshes(mesh_sources(source, man)), "finger.xml", source, gravity=grav)
        return load(str(files.pop("finger.xml")), {k: v for k, v in files.items() if isinstance(v, bytes)})
    from rjcad.mjcf.model import spec_from_model
    from rjcad.mjcf.spec import to_xml
    from rjcad.physics.finger_sources import load_finger_model

    return load(to_xml(spec_from_model(load_finger_model(source), gravity=grav)))
