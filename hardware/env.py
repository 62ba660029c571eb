"""The process environment rclpy needs, and a clear error when it is missing.

The ROS 2 Jazzy wheels from PyPI (``pip install -e '.[ros]'``) put their shared
libraries in ``site-packages/ros_*.libs`` and ``<venv>/lib``. A ``.pth`` file of the
``ros-wheels-bootstrapper`` package re-executes every interpreter of the venv once
with ``LD_LIBRARY_PATH`` pointing there (and ``_ROS_WHEELS_BOOTSTRAP_COMPLETE=1`` so it
happens only once). A process started with that flag but *without* the library path
cannot import rclpy ("librcl_action.so: cannot open shared object file"):
``ros_env`` builds a complete environment for subprocesses so this cannot happen.

Discovery: a process of this project that finds ``ROS_AUTOMATIC_DISCOVERY_RANGE``
unset sets it to ``LOCALHOST`` (DDS then never multicasts on the network). To reach
a real Create 3 on the network, export ``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET``
yourself (docs/ros2.md). ``RMW_IMPLEMENTATION`` defaults to ``rmw_fastrtps_cpp``, the
middleware the ``ros`` extra installs.

Nothing here imports rclpy at module import time.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from pathlib import Path
from types import ModuleType

from pmnav_bt.errors import PmNavError

DEFAULT_RMW = "rmw_fastrtps_cpp"
DISCOVERY_VAR = "ROS_AUTOMATIC_DISCOVERY_RANGE"
BOOTSTRAP_FLAG = "_ROS_WHEELS_BOOTSTRAP_COMPLETE"
INSTALL_HINT = "install the ROS 2 extra: pip install -e '.[ros]'"


class RosUnavailableError(PmNavError):
    """rclpy (the ROS 2 Python client) cannot be imported or started."""


def ros_library_dirs(prefix: str | None = None) -> list[str]:
    """The folders holding the ROS wheels' shared libraries, for ``LD_LIBRARY_PATH``."""
    prefix = prefix or sys.prefix
    site = Path(prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}"
    site = site / "site-packages"
    dirs = [str(Path(prefix) / "lib")]
    if site.is_dir():
        dirs += sorted(str(p.resolve()) for p in site.glob("ros_*.libs") if p.is_dir())
    return dirs


def domain_id_for(seed: int) -> int:
    """A ROS_DOMAIN_ID in 1..101 derived from ``seed`` (a pid, say): 0 and the
    high, port-hungry ids are avoided."""
    return 1 + int(seed) % 101


def ros_env(
    base: Mapping[str, str] | None = None,
    *,
    domain_id: int | None = None,
    discovery_range: str | None = "LOCALHOST",
) -> dict[str, str]:
    """A complete environment for a subprocess that uses rclpy.

    Copies ``base`` (default: this process's environment), adds the ROS wheels'
    library folders to ``LD_LIBRARY_PATH`` (with the bootstrapper's flag, so the
    child does not re-execute itself), sets ``RMW_IMPLEMENTATION`` if unset, and
    ``ROS_DOMAIN_ID`` / ``ROS_AUTOMATIC_DISCOVERY_RANGE`` when given (``None`` keeps
    what ``base`` has).
    """
    env = dict(os.environ if base is None else base)
    parts = [p for p in env.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p]
    for d in reversed(ros_library_dirs()):
        if d not in parts:
            parts.insert(0, d)
    env["LD_LIBRARY_PATH"] = os.pathsep.join(parts)
    env[BOOTSTRAP_FLAG] = "1"
    env.setdefault("RMW_IMPLEMENTATION", DEFAULT_RMW)
    if domain_id is not None:
        if not 0 <= int(domain_id) <= 232:
            raise ValueError(f"ROS_DOMAIN_ID must be in 0..232, not {domain_id}")
        env["ROS_DOMAIN_ID"] = str(int(domain_id))
    if discovery_range is not None:
        env[DISCOVERY_VAR] = discovery_range
    env.setdefault("PYTHONUNBUFFERED", "1")
    return env


def prepare_process_env() -> None:
    """Before rclpy starts in this process: safe defaults for discovery and the RMW.

    ``ROS_AUTOMATIC_DISCOVERY_RANGE`` defaults to LOCALHOST and ``RMW_IMPLEMENTATION``
    to rmw_fastrtps_cpp; values already set are kept. (rcl reads both when the
    context starts, so setting them here, before ``rclpy.init``, takes effect.)
    """
    os.environ.setdefault(DISCOVERY_VAR, "LOCALHOST")
    os.environ.setdefault("RMW_IMPLEMENTATION", DEFAULT_RMW)


def import_rclpy() -> ModuleType:
    """``rclpy``, after ``prepare_process_env``; RosUnavailableError with the fix if it fails."""
    prepare_process_env()
    try:
        import rclpy
    except ImportError as err:
        msg = str(err).splitlines()[0] if str(err) else type(err).__name__
        if "cannot open shared object" in msg:
            raise RosUnavailableError(
                f"rclpy is installed but its libraries are not on LD_LIBRARY_PATH ({msg}); "
                "run it with the venv's python or console scripts (the ros-wheels-bootstrapper "
                "sets the path), or start it with pmnav_bt.hardware.env.ros_env()"
            ) from None
        raise RosUnavailableError(f"rclpy is not importable ({msg}); {INSTALL_HINT}") from None
    return rclpy


def rclpy_available() -> tuple[bool, str]:
    """(True, "") when rclpy imports; else (False, the reason)."""
    try:
        import_rclpy()
    except RosUnavailableError as err:
        return False, str(err)
    return True, ""
