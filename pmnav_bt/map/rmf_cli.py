"""``pmnav map import-rmf``: import, write, list what was skipped, draw over the drawing."""

from __future__ import annotations

from pathlib import Path

import typer

from pmnav_bt.loading import check_output_file


def import_rmf_command(rmf: Path, out: Path, level: str | None, image: Path | None) -> None:
    """Import ``level`` of ``rmf`` to ``out`` (and its grid beside it); exit 0 when it validates."""
    from pmnav_bt.map.rmf_import import drawing_plan, import_rmf, write_import

    check_output_file(out, "--out", (".yaml", ".yml"))
    if image is not None:
        check_output_file(image, "--image", (".png", ".jpg", ".jpeg"))
    from pmnav_bt.map.rmf_site import is_multi_level

    if level is None and is_multi_level(rmf):
        _import_site(rmf, out, image)
        return
    imp = import_rmf(rmf, out, level)
    write_import(imp, out)
    b = imp.building
    for line in imp.skipped:
        typer.echo(f"skipped: {line}")
    typer.echo(
        f"wrote {out} and {imp.data['floor_plan']['ros_map']} (level {imp.level.name}, "
        f"{imp.level.scale:.4f} m per drawing pixel): {len(b.waypoints)} key waypoints, "
        f"{len(b.edges)} corridors, {len(b.rooms)} rooms from {imp.named_doors} named doors, "
        f"{len(b.landmarks)} landmarks ({imp.spurs} spur(s) to doors off the lanes, "
        f"{imp.cut_lanes} lane(s) cut at a wall or door), {len(imp.skipped)} item(s) skipped"
    )
    if image is not None:
        from pmnav_bt.map.priori_map import parse_building
        from pmnav_bt.render.annotate import render_annotated_map

        plan = drawing_plan(imp)
        render_annotated_map(
            parse_building(b), path=image, floor_plan=plan if plan is not None else imp.grid
        )
        under = " (over the walls' grid: the drawing is not there)" if plan is None else ""
        typer.echo(f"wrote {image}{under}")


def _import_site(rmf: Path, out: Path, image: Path | None) -> None:
    """Every level of a multi-level RMF building: a building file per level and the site."""
    from pmnav_bt.map.rmf_site import import_rmf_site
    from pmnav_bt.map.site_cli import render_site_images
    from pmnav_bt.map.site_map import parse_site

    imported = import_rmf_site(rmf, out)
    for name, imp in imported.levels.items():
        b = imp.building
        for line in imp.skipped:
            typer.echo(f"skipped: level {name}: {line}")
        typer.echo(
            f"wrote {imp.data['name']} to {out.with_name(f'{out.stem}_{name}.yaml')} (level "
            f"{name}): {len(b.waypoints)} key waypoints, {len(b.edges)} corridors, "
            f"{len(b.rooms)} rooms, {len(b.landmarks)} landmarks"
        )
    for line in imported.skipped:
        typer.echo(f"skipped: {line}")
    site = imported.site
    lifts = ", ".join(f"{k.id} ({', '.join(k.lobbies)})" for k in site.lifts)
    typer.echo(f"wrote {out}: site {site.name}, {len(site.levels)} levels, lifts {lifts}")
    if image is not None:
        for path in render_site_images(parse_site(site), image):
            typer.echo(f"wrote {path}")
