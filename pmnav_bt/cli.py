"""The core commands of ``pmnav`` (buildings, backends, validate, map, plan, ...).

``pmnav_bt.experiments.cli`` mounts ``pmnav sim`` and ``pmnav tree`` on this app and is
the program's entry point: the core knows neither the simulator nor the tree.

A user error (bad file, unknown room, ...) prints one line on stderr and exits
with status 2; ``pmnav validate`` exits 1 when the file has problems.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import typer

from pmnav_bt.cli_values import run_cli
from pmnav_bt.errors import BuildingFileError, PmNavError
from pmnav_bt.loading import check_output_file
from pmnav_bt.map.updates_cli import map_updates
from pmnav_bt.webview.cli import view

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")

app = typer.Typer(
    add_completion=False,
    pretty_exceptions_enable=False,
    no_args_is_help=True,
    help="PM-Nav BT: find a named room in a functional building from a prior floor plan.",
)

FILE_HELP = (
    "A building or site file (YAML) or the name of a built-in building or site (see "
    "'pmnav buildings')."
)
LEVEL_HELP = "Only this level of a site (a building file's one level is L1)."


def _priori_map(file: str):
    from pmnav_bt.map.catalogue import open_building
    from pmnav_bt.map.priori_map import parse_building

    return parse_building(open_building(file))


def _folder(file: str) -> Path:
    """The folder a building file's relative paths (floor plan) are resolved against."""
    from pmnav_bt.map.catalogue import resolve_building_path

    return resolve_building_path(file).parent


@app.command()
def buildings() -> None:
    """List the built-in buildings and the generated families."""
    from pmnav_bt.map.catalogue import (
        DEV_SEEDS,
        FAMILIES,
        HELDOUT_SEEDS,
        MIXED_FAMILY,
        MIXED_SITE_FAMILY,
        SITE_FAMILIES,
        builtin_buildings,
        load_building,
    )
    from pmnav_bt.map.site import builtin_sites, load_site

    for name in builtin_buildings():
        b = load_building(name)
        typer.echo(f"{name:<16} {b.kind:<9} {len(b.rooms):>3} rooms  {b.description}")
    for name in builtin_sites():
        s = load_site(name)
        rooms = sum(len(lv.building.rooms) for lv in s.levels)
        typer.echo(f"{name:<16} {'site':<9} {rooms:>3} rooms  {s.description}")
    typer.echo(
        f"\nGenerated families ({', '.join(FAMILIES)}): FAMILY_SEED names one member, FAMILY:N "
        f"the first N; {MIXED_FAMILY}:N takes hospital, school and office in turn. hospital, "
        f"school, office and {MIXED_FAMILY} have development seeds {DEV_SEEDS.start}-"
        f"{DEV_SEEDS.stop - 1} and held-out seeds {HELDOUT_SEEDS.start}-{HELDOUT_SEEDS.stop - 1} "
        "(FAMILY_heldout:N; for evaluation only, never tuned on). See docs/scale.md."
    )
    typer.echo(
        f"Generated sites of 2-4 levels ({', '.join(SITE_FAMILIES)}; {MIXED_SITE_FAMILY}:N "
        "takes the three in turn), seeded and ranged alike: hospital_site_3, "
        f"{MIXED_SITE_FAMILY}:N, {MIXED_SITE_FAMILY}_heldout:N. See docs/lifts.md."
    )


@app.command()
def backends() -> None:
    """List every registered back end of each seam (choose with --set SEAM.backend=NAME)."""
    from pmnav_bt.config import Config
    from pmnav_bt.registry import REGISTRIES

    defaults = Config()
    for seam, registry in REGISTRIES.items():
        default = getattr(defaults, seam).backend
        for name in registry.names():
            spec = registry.spec(name)
            tags = ["default"] * (name == default) + spec.tags
            tag = f" [{', '.join(tags)}]" if tags else ""
            typer.echo(f"{seam + '.backend':<17} {name:<12} {spec.summary}{tag}")


@app.command()
def validate(
    file: str = typer.Argument(..., help=FILE_HELP),
    strict: bool = typer.Option(False, "--strict", help="Treat warnings as problems (exit 1)."),
    level: str | None = typer.Option(None, "--level", help=LEVEL_HELP),
) -> None:
    """Check a building or site file: list every problem (exit 1), then warnings about runs."""
    from pmnav_bt.map.catalogue import open_building
    from pmnav_bt.map.checks import building_warnings
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.map.site_cli import names_site, validate_site
    from pmnav_bt.map.unreached import unreached_warnings_of

    if level is not None or names_site(file):
        validate_site(file, strict, level)
        return

    try:
        b = open_building(file)
    except BuildingFileError as err:
        for line in err.listing():
            typer.echo(line, err=True)
        raise typer.Exit(1) from None
    pm = parse_building(b)
    typer.echo(
        f"{file}: OK: {b.name}: {len(b.rooms)} rooms, {len(b.landmarks)} landmarks, "
        f"{len(b.waypoints)} key waypoints, {len(b.edges)} corridors, {len(pm.segments)} segments"
    )
    warnings = building_warnings(b, _folder(file)) + unreached_warnings_of(b, _folder(file))
    for w in warnings:
        typer.echo(f"{file}: warning: {w}", err=True)
    if warnings:
        typer.echo(f"{len(warnings)} warning(s)", err=True)
        if strict:
            raise typer.Exit(1)


@app.command("map")
def map_(
    file: str = typer.Argument(..., help=FILE_HELP),
    as_json: bool = typer.Option(False, "--json", help="Print the priori-map as JSON."),
    image: Path | None = typer.Option(None, "--image", help="Write the annotated map PNG here."),
    grid: float | None = typer.Option(
        None, "--grid", help="Draw a metre grid on the image, lines this many metres apart."
    ),
    level: str | None = typer.Option(None, "--level", help=LEVEL_HELP),
) -> None:
    """Print the semantic priori-map (structured text or JSON); optionally draw it (a site:
    each level's, with the lifts; one image per level, FILE_LEVEL.png)."""
    from pmnav_bt.map.site_cli import names_site, show_site_map

    if image is not None:
        check_output_file(image, "--image", IMAGE_SUFFIXES)
    if level is not None or names_site(file):
        show_site_map(file, level, as_json, image, grid)
        return
    pm = _priori_map(file)
    typer.echo(json.dumps(pm.to_dict(), indent=2) if as_json else pm.to_text(), nl=not as_json)
    if image is not None:
        from pmnav_bt.render.annotate import render_annotated_map

        render_annotated_map(pm, path=image, base_dir=_folder(file), grid_m=grid)
        typer.echo(f"wrote {image}", err=True)


@app.command("map-draft")
def map_draft(
    source: Path = typer.Argument(
        ..., help="A ROS map_server YAML, or a floor-plan drawing (PNG/JPEG) with --scale."
    ),
    out: Path = typer.Option(..., "-o", "--out", help="The building file to write."),
    name: str | None = typer.Option(None, help="Building name (default: the source's file name)."),
    image: Path | None = typer.Option(None, "--image", help="Draw the extraction steps here."),
    scale: float | None = typer.Option(None, help="A drawing's metres per pixel."),
    scale_from: str | None = typer.Option(
        None, help="A drawing's scale from two pixels and their distance: X1,Y1,X2,Y2,METRES."
    ),
    door_max: float | None = typer.Option(None, help="Widest door (m); shorter places cut."),
    corridor_min: float | None = typer.Option(None, help="Narrowest corridor (m)."),
    open_width: float | None = typer.Option(None, help="Wider (m) is an open area, a hall."),
    part_min: float | None = typer.Option(None, help="Shortest part apart kept (m)."),
    corridor_ratio: float | None = typer.Option(
        None, help="A corridor is this many times longer than wide (else a room)."
    ),
    link_max: float | None = typer.Option(None, help="Longest link joining a part (m)."),
    wall_min: float | None = typer.Option(
        None, help="A dead end walled (not fading into unknown) along less of it goes (0-1)."
    ),
    lined_min: float | None = typer.Option(
        None, help="A loop or dead end with less of its sides lined by parallel walls goes (0-1)."
    ),
    clutter: float | None = typer.Option(None, help="Obstacles this small (m) are filled."),
) -> None:
    """Draft a building file from an occupancy grid or a drawing ('pmnav map draft SRC -o FILE')."""
    from pmnav_bt.map.draft import draft_source, draw_steps

    out.parent.mkdir(parents=True, exist_ok=True)
    knobs = {  # the thresholds given; DraftParams holds the defaults (docs/real-maps.md)
        k: v
        for k, v in (
            ("door_max_m", door_max),
            ("doorway_max_m", door_max),
            ("corridor_min_m", corridor_min),
            ("open_width_m", open_width),
            ("part_min_m", part_min),
            ("corridor_ratio", corridor_ratio),
            ("link_max_m", link_max),
            ("wall_min", wall_min),
            ("lined_min", lined_min),
            ("clutter_m", clutter),
        )
        if v is not None
    }
    b, d, text, plan = draft_source(source, out, name, scale, scale_from, knobs)
    out.write_text(text, encoding="utf-8")
    if image is not None:
        draw_steps(plan, d, image)
    for w in d.warnings:
        typer.echo(f"{out}: warning: {w}", err=True)
    typer.echo(
        f"wrote {out}: {len(b.waypoints)} key waypoints, {len(b.edges)} corridors, "
        f"{len(b.rooms)} door candidates, {len(d.open_areas)} open area(s); "
        "fill in the todo notes, then 'pmnav validate'"
    )


@app.command("map-import-rmf")
def map_import_rmf(
    rmf: Path = typer.Argument(..., help="An Open-RMF traffic-editor file (*.building.yaml)."),
    out: Path = typer.Option(
        ..., "-o", "--out", help="The building file to write (YAML); a site file for all levels."
    ),
    level: str | None = typer.Option(
        None,
        help="The level to import (default: a one-level file's level; with several, every "
        "level, as a site with OUT_<level>.yaml beside it).",
    ),
    image: Path | None = typer.Option(
        None, "--image", help="Draw the imported map over the level's drawing here (PNG)."
    ),
) -> None:
    """Import an Open-RMF building: one level, or every level as a site (also: 'pmnav map
    import-rmf FILE -o OUT')."""
    from pmnav_bt.map.rmf_cli import import_rmf_command

    import_rmf_command(rmf, out, level, image)


@app.command()
def annotate(file: Path = typer.Argument(..., help="The building file to edit (YAML).")) -> None:
    """Edit a building over its floor plan in a window (Tk): rooms, waypoints, corridors, signs."""
    from pmnav_bt.render.tk_annotate import run

    run(file)


app.command("view")(view)
app.command("map-updates")(map_updates)


def _error_line(err: PmNavError) -> str:
    return err.summary() if isinstance(err, BuildingFileError) else str(err)


def main(argv: list[str] | None = None) -> None:
    """Entry point: run the app; user errors become one line on stderr and exit status 2."""
    args = list(sys.argv[1:] if argv is None else argv)
    sub = ("draft", "import-rmf", "updates")  # 'pmnav map FILE' is a command, so
    if args[:1] == ["map"] and args[1:2] and args[1] in sub:  # 'map draft' is map-draft
        args = [f"map-{args[1]}", *args[2:]]
    run_cli(app, args, "pmnav", _error_line)


if __name__ == "__main__":  # pragma: no cover
    main()
