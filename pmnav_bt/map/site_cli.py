"""The commands that take a building, given a site of several levels: ``pmnav validate``,
``pmnav map`` and ``pmnav plan`` with a site file (or a built-in site's name).

A one-floor building file goes the way it always went (``pmnav_bt/cli.py``); these
functions report and draw per level: each level's problems and warnings under its name,
its priori-map text with the lifts that join it, and one annotated image per level with
the lift lobbies marked with the levels they go to.
"""

from __future__ import annotations

from pathlib import Path

import typer

from pmnav_bt.errors import BuildingFileError
from pmnav_bt.loading import InputFileError, load_yaml
from pmnav_bt.map.site import BUILTIN_SITES_DIR, Site, is_site_data, open_site, resolve_site_path
from pmnav_bt.map.site_map import SiteMap, parse_site


def names_site(file: str) -> bool:
    """True when ``file`` names a site file or a built-in site (not a one-floor building);
    a file that cannot be read is left to the building commands to report."""
    try:
        path = resolve_site_path(file)
    except BuildingFileError:
        return False
    if path.parent == BUILTIN_SITES_DIR:
        return True
    try:
        return is_site_data(load_yaml(path, "building"))
    except InputFileError:
        return False


def level_folder(site: Site, level: str) -> Path:
    """Where a level's relative paths (its floor plan) are resolved: beside its file, or
    beside the site file for a building written inline."""
    lv = site.level(level)
    if lv.path is not None:
        return lv.path.parent
    return site.path.parent if site.path is not None else Path(".")


def validate_site(file: str, strict: bool, level: str | None) -> None:
    """``pmnav validate SITE``: every problem (exit 1), else each level's summary and
    warnings, then the site's."""
    from pmnav_bt.map.checks import building_warnings
    from pmnav_bt.map.unreached import unreached_warnings_of

    try:
        site = open_site(file)
    except BuildingFileError as err:
        for line in err.listing():
            typer.echo(line, err=True)
        raise typer.Exit(1) from None
    sm = parse_site(site)
    names = [site.level(level).name] if level is not None else list(site.level_names)
    warned = 0
    for name in names:
        b, pm = site.level(name).building, sm.maps[name]
        lifts = ", ".join(lift.id for lift in site.lifts_at(name)) or "none"
        typer.echo(
            f"{file}: level {name}: OK: {b.name}: {len(b.rooms)} rooms, {len(b.landmarks)} "
            f"landmarks, {len(b.waypoints)} key waypoints, {len(b.edges)} corridors, "
            f"{len(pm.segments)} segments; lifts {lifts}"
        )
        folder = level_folder(site, name)
        warnings = building_warnings(b, folder) + unreached_warnings_of(b, folder)
        for w in warnings:
            typer.echo(f"{file}: level {name}: warning: {w}", err=True)
        warned += len(warnings)
    counts = ", ".join(
        f"{n} {what}" + ("s" * (n != 1))
        for n, what in ((len(site.levels), "level"), (len(site.lifts), "lift"))
    )
    typer.echo(f"{file}: OK: site {site.name}: {counts}, {len(site.stairs)} stairs")
    if warned:
        typer.echo(f"{warned} warning(s)", err=True)
        if strict:
            raise typer.Exit(1)


def show_site_map(
    file: str, level: str | None, as_json: bool, image: Path | None, grid: float | None
) -> None:
    """``pmnav map SITE``: the site's priori-map text (or JSON) and an image per level."""
    import json

    sm = parse_site(open_site(file))
    if as_json:
        typer.echo(json.dumps(sm.to_dict(), indent=2), nl=False)
    else:
        typer.echo(sm.to_text(level))
    if image is not None:
        for out in render_site_images(sm, image, level, grid_m=grid):
            typer.echo(f"wrote {out}", err=True)


def level_image_path(image: Path, level: str, one: bool) -> Path:
    """The image file of ``level``: ``image`` itself when one level is drawn, else the
    level's name added to its stem (``map.png`` -> ``map_L2.png``)."""
    return image if one else image.with_name(f"{image.stem}_{level}{image.suffix}")


def render_site_images(
    sm: SiteMap,
    image: Path,
    level: str | None = None,
    paths: dict[str, list[tuple[float, float]]] | None = None,
    grid_m: float | None = None,
) -> list[Path]:
    """Draw each level's annotated priori-map (or ``level``'s only), its lift lobbies
    marked with the levels they go to, and ``paths`` (level -> map points) on their
    levels; return the files written."""
    from pmnav_bt.render.annotate import render_annotated_map

    site = sm.site
    names = [site.level(level).name] if level is not None else list(site.level_names)
    written = []
    for name in names:
        pm = sm.maps[name]
        b = pm.building
        marks = []
        for lift in site.lifts_at(name):
            to = ", ".join(lv for lv in lift.lobbies if lv != name)
            marks.append((b.landmark(lift.lobbies[name]).pos, f"{lift.id} -> {to}"))
        out = level_image_path(image, name, len(names) == 1)
        render_annotated_map(
            pm,
            path=out,
            path_xy=(paths or {}).get(name),
            base_dir=level_folder(site, name),
            grid_m=grid_m,
            marks=marks if not sm.single else (),
        )
        written.append(out)
    return written
