"""``rjcad urdf``: the URDF of a built finger or joint (links, revolute joints, meshes in metres)."""

from __future__ import annotations

from pathlib import Path

import click

from rjcad.cli.options import OutDir, allow_outside_option


@click.command()
@click.argument("manifest", type=click.Path(dir_okay=False))
@click.option(
    "--out",
    "out_dir",
    type=OutDir(),
    default="urdf",
    show_default=True,
    help="Directory to write <manifest stem>.urdf and meshes/<body>.stl into (its meshes/ is replaced whole).",
)
@allow_outside_option
def urdf(manifest, out_dir, allow_outside):
    """Write the URDF (SI units) of a finger or joint built by `rjcad finger` or `rjcad joint`: its manifest
    MANIFEST.json and, beside it, its per-body STLs or its 3MF. URDF holds no springs and no tendon: they are
    written as comments (the MJCF of `rjcad mjcf` has them)."""
    from rjcad.io.manifest import Manifest
    from rjcad.io.outputs import check_writable, write_set
    from rjcad.mjcf.export import check_manifest, mesh_sources, read_meshes
    from rjcad.mjcf.urdf import check_names, robot_name, urdf_files

    man = Manifest.read(manifest)
    check_manifest(man, Path(manifest).name)
    check_names(man, Path(manifest).name)
    check_writable(out_dir)
    meshes = read_meshes(mesh_sources(manifest, man, allow_outside))
    name = robot_name(manifest, man)
    files = urdf_files(man, meshes, name, manifest)
    write_set(out_dir, files)
    n = len(man.joints)
    click.echo(
        f"URDF written to {Path(out_dir) / f'{name}.urdf'} ({n} revolute joint{'s' if n > 1 else ''}, "
        f"{len(files) - 1} meshes in {Path(out_dir) / 'meshes'}); springs and tendon as comments"
    )
