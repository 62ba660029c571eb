"""The cross-level tier in the evaluation (issue 40): episodes across levels in the
episode file, the tier's selection and refusal, the same evaluation path as the one-level
tiers (``evaluate``), and its table in the report."""

from __future__ import annotations

import json
import math

import pytest
import yaml
from site_kit import two_level_site

from pmnav_bt.config import Config
from pmnav_bt.eval.metrics import EpisodeResult
from pmnav_bt.eval.tiers import CROSS_LEVEL, TIER_NAMES, parse_tiers
from pmnav_bt.experiments.cli import main
from pmnav_bt.experiments.evaluation import episodes_for, evaluate
from pmnav_bt.experiments.report_tables import cross_level_table
from pmnav_bt.experiments.variants import variant_configs
from pmnav_bt.sim.episodes import (
    EpisodeFileError,
    generate_episodes,
    load_episodes,
    save_episodes,
)
from pmnav_bt.sim.site_episodes import SiteEpisode, generate_site_episodes


def _site_file(tmp_path):
    f = tmp_path / "two.yaml"
    f.write_text(yaml.safe_dump(two_level_site()))
    return f


def test_site_episodes_round_trip_beside_one_level_ones(tmp_path):
    eps = [*generate_site_episodes("hospital_2l", 3, seed=1)]
    eps += generate_episodes("fig2_hospital", "easy", 2, seed=1)
    eps += generate_site_episodes(str(_site_file(tmp_path)), 1, seed=1)
    f = save_episodes(eps, tmp_path / "eps.json")
    back = load_episodes(f)
    assert back == eps
    assert [type(e).__name__ for e in back].count("SiteEpisode") == 4
    assert back[0].site == "hospital_2l"  # a built-in by its name: the file travels
    assert back[-1].site == str((tmp_path / "two.yaml").resolve())  # any other by its path


def test_a_bad_site_entry_names_each_problem(tmp_path):
    a, b = (e.to_dict() for e in generate_site_episodes("hospital_2l", 2))
    a["extra"] = 1
    del a["rides"]
    b["tier"] = "easy"
    f = tmp_path / "eps.json"
    f.write_text(json.dumps([a, b]))  # a bare list is an episode file too
    with pytest.raises(EpisodeFileError) as info:
        load_episodes(f)
    text = "\n".join(str(p) for p in info.value.problems)
    assert "episodes[0].extra: unknown key" in text
    assert "episodes[0].rides: required key is missing" in text
    assert "episodes[1].tier: an episode with a site is cross_level" in text


def test_all_tiers_include_cross_level_and_a_site_poses_only_it():
    assert parse_tiers("all") == [*TIER_NAMES, CROSS_LEVEL]
    eps, notes = episodes_for(["hospital_2l", "fig2_hospital"], parse_tiers("all"), 1, 0)
    tiers = {(e.building, e.tier) for e in eps}
    assert ("hospital_2l", CROSS_LEVEL) in tiers and ("fig2_hospital", "easy") in tiers
    assert ("fig2_hospital", CROSS_LEVEL) not in tiers
    assert not any(e.tier != CROSS_LEVEL for e in eps if e.building == "hospital_2l")
    assert notes == [
        "hospital_2l is a site of several levels: its episodes are cross_level, "
        "not easy, medium, hard"
    ]


def test_cross_level_alone_on_one_level_is_refused(capsys):
    eps, notes = episodes_for(["fig2_hospital"], [CROSS_LEVEL], 2, 0)
    assert eps == [] and "one level each" in notes[0]
    with pytest.raises(SystemExit) as info:
        main(["sim", "episodes", "fig2_hospital", "--tier", "cross_level", "-n", "2"])
    err = capsys.readouterr().err.strip()
    assert info.value.code == 2
    assert err.startswith("pmnav: error: no cross_level episodes in fig2_hospital: one level")


def test_a_site_episode_that_cannot_run_is_an_errored_row_of_its_tier(tmp_path):
    f = _site_file(tmp_path)
    ep = generate_site_episodes(str(f), 1)[0]
    f.unlink()  # the site is gone where it runs
    rs = evaluate([ep], variant_configs(Config(), ["pmnav_oracle"]), jobs=1)
    (r,) = rs["pmnav_oracle"]
    assert r.error is not None and r.tier == CROSS_LEVEL and r.building == ep.site


def test_the_cross_level_table_counts_rides_full_lifts_and_failures():
    def row(ok, full, reason=None):
        return EpisodeResult(
            "e", CROSS_LEVEL, ok, 0.5 if ok else 0.0, 30.0, 90, failure_reason=reason,
            rides=1, lifts_full=full,
        )  # fmt: skip

    results = {
        "pmnav": [row(True, 1), row(False, 2, "LIFT_FULL: full three times")],
        "pmnav_oracle": [row(True, 0), row(True, 0)],
        "coarse_only": [EpisodeResult("e", "easy", True, 1.0, 3.0, 5)],
    }
    lines = cross_level_table(results).splitlines()
    assert len(lines) == 4  # the header, its rule and a row per variant with cross_level
    assert lines[2].startswith("| PM-Nav | 2 | 50.0 | 25.0 | 2 | 3 | LIFT_FULL 1 |")
    assert "oracle" in lines[3] and lines[3].endswith("| 100.0 | 50.0 | 2 | 0 | none |")
    assert cross_level_table({"coarse_only": results["coarse_only"]}) is None


def test_an_oracle_cross_level_evaluation_on_hospital_2l(tmp_path):
    # One ride in the clean world (about 15 s on an idle core): the site's run in evaluate.
    eps = generate_site_episodes("hospital_2l", 1, seed=0)
    rs = evaluate(eps, variant_configs(Config(), ["pmnav_oracle"]), jobs=1)
    (r,) = rs["pmnav_oracle"]
    assert isinstance(eps[0], SiteEpisode)
    assert r.error is None and r.success, r.failure_reason
    assert r.rides == 1 and r.lifts_full == 0 and r.tier == CROSS_LEVEL
    assert 0 < r.spl <= 1 and math.isfinite(r.shortest_path_length)


def test_sim_run_takes_a_stored_site_episode(tmp_path, capsys):
    f = _site_file(tmp_path)
    eps = save_episodes(generate_site_episodes(str(f), 1), tmp_path / "eps.json")
    f.unlink()  # the run opens the episode's own site: its error says so, in one line
    with pytest.raises(SystemExit) as info:
        main(["sim", "run", "--episodes", str(eps), "--out", str(tmp_path / "o")])
    out, err = capsys.readouterr()
    last = err.strip().splitlines()[-1]
    assert info.value.code == 2 and "(cross_level), start on L" in out  # the site's run
    assert last.startswith("pmnav: error: ") and "two.yaml" in last


@pytest.mark.world
def test_a_site_s_level_worlds_and_wall_maps_follow_sim_walls(rmf_maps, tmp_path):
    """``sim.walls=grid`` builds each level's world from its grid, and the grid is that
    level's map of the walls, as in a one-level episode (the clinic's lifts included)."""
    from pmnav_bt.config import load_config
    from pmnav_bt.experiments.site_run import level_grids, level_worlds
    from pmnav_bt.map.rmf_site import import_rmf_site
    from pmnav_bt.map.site import read_site_file

    out = tmp_path / "clinic.yaml"
    import_rmf_site(rmf_maps / "clinic" / "clinic.building.yaml", out)
    site = read_site_file(out)
    assert set(level_grids(site, Config()).values()) == {None}
    cfg = load_config(None, ["sim.walls=grid"])
    assert None not in level_grids(site, cfg).values()
    worlds: dict = {}
    try:
        level_worlds(site, cfg, 0, worlds)
        assert {w.wall_source for w in worlds.values()} == {"grid"}
        assert all(len(w.cabins) == 3 for w in worlds.values())
    finally:
        for w in worlds.values():
            w.close()
