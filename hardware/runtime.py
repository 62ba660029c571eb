"""An rclpy context with an executor spinning in a background thread, and signal handling.

rclpy's own SIGINT handler shuts the context down at once, after which nothing can
be published, not even the zero ``cmd_vel`` that stops the robot. ``RosRuntime``
starts rclpy without its handlers (``SignalHandlerOptions.NO``); ``install_signals``
sets handlers that only *request* a shutdown, so the owner can stop the robot first
and then call ``shutdown()``. A second Ctrl-C raises KeyboardInterrupt.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Callable
from typing import Any, NoReturn, TypeVar

from pmnav_bt.errors import PmNavError
from pmnav_bt.hardware.env import import_rclpy

T = TypeVar("T")


class RosArgumentsError(PmNavError):
    """rclpy could not start with the given arguments (a bad ``--ros-args`` rule)."""


class RosRuntime:
    """rclpy context + an executor (single-threaded unless ``threads`` > 1) spun by a
    daemon thread."""

    def __init__(
        self, args: list[str] | None = None, threads: int = 1, domain_id: int | None = None
    ) -> None:
        rclpy = import_rclpy()
        from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
        from rclpy.signals import SignalHandlerOptions

        self.rclpy = rclpy
        self.context = rclpy.Context()
        try:
            rclpy.init(
                args=args,
                context=self.context,
                domain_id=domain_id,
                signal_handler_options=SignalHandlerOptions.NO,
            )
        except Exception as err:  # rclpy raises RCLError for bad --ros-args
            msg = str(err).split(", at ")[0]
            raise RosArgumentsError(
                f"{msg} (an empty string parameter must be quoted: -p name:=\"''\")"
            ) from None
        if threads > 1:
            self.executor = MultiThreadedExecutor(num_threads=threads, context=self.context)
        else:
            self.executor = SingleThreadedExecutor(context=self.context)
        self.stop_requested = threading.Event()
        self._thread: threading.Thread | None = None
        self._nodes: list = []
        self._signals = 0

    def add(self, node) -> None:
        self._nodes.append(node)
        self.executor.add_node(node)

    def start(self) -> RosRuntime:
        """Spin the executor in a background thread."""
        self._thread = threading.Thread(target=self._spin, name="rclpy-executor", daemon=True)
        self._thread.start()
        return self

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        try:
            self.executor.spin()
        except (ExternalShutdownException, KeyboardInterrupt):
            pass
        except Exception as err:  # noqa: BLE001 - a dying executor must not hang the process
            if self.context.ok():
                print(f"rclpy executor stopped: {err}", flush=True)
        finally:
            self.stop_requested.set()

    def install_signals(self, on_request: Callable[[], None] | None = None) -> None:
        """SIGINT/SIGTERM request a shutdown (``stop_requested``); a second one raises
        KeyboardInterrupt. Call from the main thread."""

        def handler(signum, _frame) -> None:
            self._signals += 1
            self.stop_requested.set()
            if on_request is not None:
                on_request()
            if self._signals > 1:
                raise KeyboardInterrupt

        signal.signal(signal.SIGINT, handler)
        signal.signal(signal.SIGTERM, handler)

    def shutdown(self) -> None:
        """Destroy the nodes, stop the executor and the context. Idempotent."""
        self.stop_requested.set()
        for node in self._nodes:
            try:
                self.executor.remove_node(node)
                node.destroy_node()
            except Exception:  # noqa: BLE001
                pass
        self._nodes.clear()
        with contextlib.suppress(Exception):
            self.executor.shutdown(timeout_sec=2.0)
        self.rclpy.try_shutdown(context=self.context)
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)


def run_node(
    program: str,
    node_name: str,
    args: list[str],
    start: Callable[[Any, RosRuntime], T],
    *,
    serve: Callable[[T], None] | None = None,
    on_signal: Callable[[T], None] | None = None,
    before_shutdown: Callable[[T], None] | None = None,
    after_shutdown: Callable[[T], None] | None = None,
) -> NoReturn:
    """A console script's life on one rclpy node, then ``sys.exit``: start rclpy (exit 2 on
    a bad ``--ros-args`` or no rclpy), ``start(node, runtime)`` the program, spin, install
    the signal handlers (a signal calls ``on_signal``), ``serve`` it (default: wait for a
    stop), and on the way out ``before_shutdown`` (e.g. a last zero cmd_vel, while the
    context still lives), the runtime's shutdown, ``after_shutdown``. A ``PmNavError``
    prints ``program: message`` and exits 1."""
    try:
        runtime = RosRuntime(args=args)
    except PmNavError as err:  # rclpy missing, or bad --ros-args
        print(f"{program}: {err}", file=sys.stderr)
        sys.exit(2)
    from rclpy.node import Node

    node = Node(node_name, context=runtime.context)
    owner = None
    code = 0
    try:
        owner = start(node, runtime)
        runtime.add(node)
        runtime.install_signals(None if on_signal is None else lambda: on_signal(owner))
        runtime.start()
        if serve is not None:
            serve(owner)
        else:
            while not runtime.stop_requested.wait(0.2):
                pass
    except PmNavError as err:
        print(f"{program}: {err}", file=sys.stderr)
        code = 1
    except KeyboardInterrupt:
        pass
    finally:
        if owner is not None and before_shutdown is not None:
            before_shutdown(owner)
        runtime.shutdown()
        if owner is not None and after_shutdown is not None:
            after_shutdown(owner)
    sys.exit(code)
