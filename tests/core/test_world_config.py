"""The config's world section: presets fill the defaults, keys set beside them win."""

import pytest

from pmnav_bt.config import WORLD_PRESETS, load_config
from pmnav_bt.errors import ConfigError
from pmnav_bt.sim.scene import scene_rng


def test_clean_is_the_default_and_fills_nothing_in():
    w = load_config().world
    assert w.preset == "clean"
    assert (w.clutter_per_10m, w.people_per_100m, w.doors_open, w.camera_noise) == (0, 0, 0, 0)
    assert w.signage == "file" and w.appearance == "clean"


def test_realistic_preset_sets_its_values_and_a_key_beside_it_overrides():
    w = load_config(overrides=["world.preset=realistic", "world.people_per_100m=0"]).world
    assert w.clutter_per_10m == WORLD_PRESETS["realistic"]["clutter_per_10m"] > 0
    assert w.people_per_100m == 0
    assert w.signage == "random"


@pytest.mark.parametrize(
    "item, says",
    [
        ("world.preset=foggy", "world.preset"),
        ("world.light_level=[1.5,0.5]", "min <= max"),
        ("world.people_speed=[1.0]", "world.people_speed"),
        ("world.camera_exposure=[0.1,1.0]", "0.2 <= min"),
        ("world.doors_open=1.5", "world.doors_open"),
        ("world.crowds=3", "world.crowds"),
    ],
)
def test_bad_world_values_are_one_line_errors_naming_the_key(item, says):
    with pytest.raises(ConfigError, match=r"^--set: world\.") as err:
        load_config(overrides=[item])
    assert says in str(err.value) and "\n" not in str(err.value)


def test_scene_streams_are_reproducible_and_independent_per_part():
    a = scene_rng(7, "fig2_hospital", "clutter").random(4)
    assert (a == scene_rng(7, "fig2_hospital", "clutter").random(4)).all()
    assert (a != scene_rng(7, "fig2_hospital", "people").random(4)).all()
    assert (a != scene_rng(8, "fig2_hospital", "clutter").random(4)).all()
    assert (a != scene_rng(7, "school_a", "clutter").random(4)).all()


def test_a_variant_in_another_world_keeps_the_runs_own_world_keys():
    from pmnav_bt.experiments.variants import in_worlds, variant_configs, variant_title

    base = load_config(overrides=["world.people_per_100m=7", "grounder.miss_rate=0.1"])
    names = in_worlds(["pmnav", "pmnav_oracle@realistic"], ["clean", "realistic"])
    assert names == ["pmnav@clean", "pmnav@realistic", "pmnav_oracle@realistic"]
    configs = variant_configs(base, names)
    clean, real = configs["pmnav@clean"].world, configs["pmnav@realistic"].world
    assert clean.preset == "clean" and clean.clutter_per_10m == 0
    assert real.clutter_per_10m == WORLD_PRESETS["realistic"]["clutter_per_10m"]
    assert clean.people_per_100m == real.people_per_100m == 7  # the run's own change
    assert configs["pmnav@realistic"].grounder.miss_rate == 0.1
    assert variant_title("pmnav_oracle@realistic").startswith("PM-Nav, realistic world (oracle")
