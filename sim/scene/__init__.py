"""What fills a simulated building beyond its file: signage styles, clutter, people, door
states, colours and light, and the camera's flaws, as the config's ``world`` section asks.

Everything random here is drawn from ``scene_rng(seed, building, part)``: one stream per
part, so that changing how one part draws (or turning it off) leaves the others as they
were, and the same episode seed gives the same world.
"""

from __future__ import annotations

import zlib

import numpy as np


def scene_rng(seed: int, building: str, part: str) -> np.random.Generator:
    """The random stream of one ``part`` of the scene ("signage", "clutter", "people", ...)
    of ``building`` in the episode of ``seed``."""
    return np.random.default_rng(
        [int(seed) & 0xFFFFFFFF, zlib.crc32(building.encode()), zlib.crc32(part.encode())]
    )
