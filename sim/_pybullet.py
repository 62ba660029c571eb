"""pybullet, imported without its "pybullet build time" banner on stderr.

The banner is printed by C code at import, so Python's sys.stderr cannot catch it;
the file descriptor is pointed at /dev/null for the import and C's buffer flushed.
"""

from __future__ import annotations

import os
import sys


def _quiet_import():
    try:
        fd = sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):  # no real stderr (pytest capture, IDEs)
        import pybullet

        return pybullet
    sys.stderr.flush()
    saved = os.dup(fd)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, fd)
        import pybullet

        _flush_c_stdio()  # the banner sits in C's stdout buffer until flushed
    finally:
        os.dup2(saved, fd)
        os.close(saved)
        os.close(devnull)
    return pybullet


def _flush_c_stdio() -> None:
    try:
        import ctypes

        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library handle: the banner may show
        pass


p = _quiet_import()
