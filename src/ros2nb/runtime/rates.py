"""How often each timer of a node runs on a given executor, on the wall clock.

Introduced in ``06-five-promises.ipynb`` (concurrency).  A slow callback only blocks the
others on the wall clock (a service's answer and ``time.sleep`` do not wait for ``/clock``),
so this is the one place in the course that spins a node on the wall clock on an executor the
learner chose, apart from the kernel's own and the judge's subject of that notebook.
"""

from __future__ import annotations

import inspect
import threading
import time
from typing import Any

from rclpy.executors import Executor
from rclpy.node import Node

#: Seconds one ``spin_once`` of the measured executor may wait.
SPIN_WAIT_S = 0.02
#: Seconds to wait, after the measurement, for callbacks still running in other threads.
FINISH_WAIT_S = 30.0
#: Seconds to wait at most for the node's service clients to find their servers.
SERVICE_WAIT_S = 5.0


class _Running:
    """How many counted callbacks are running now (in any of the executor's threads)."""

    def __init__(self) -> None:
        self.count = 0
        self.changed = threading.Condition()

    def __enter__(self) -> None:
        with self.changed:
            self.count += 1

    def __exit__(self, *exc: Any) -> None:
        with self.changed:
            self.count -= 1
            self.changed.notify_all()


def _counted(timer: Any, counts: dict[str, int], running: _Running) -> None:
    """Count each run of ``timer``'s callback (a coroutine callback as a coroutine: the
    executor awaits it, and it runs until it returns)."""
    original = timer.callback
    name = getattr(original, '__name__', repr(original))
    counts[name] = 0

    def counted() -> Any:
        with running:
            counts[name] += 1
            return original()

    async def counted_coroutine() -> Any:  # resumed by the spin thread only: nothing to wait for
        counts[name] += 1
        return await original()

    chosen = counted_coroutine if inspect.iscoroutinefunction(original) else counted
    chosen.__name__ = chosen.__qualname__ = name
    timer.callback = chosen


def track_calls(client: Any, calls: list[Any]) -> None:
    """Keep every future the service ``client`` makes in ``calls`` (``call()`` makes its own
    through ``call_async``): cancelled, each lets a callback that waits for it return."""
    original = client.call_async

    def call_async(request: Any) -> Any:
        future = original(request)
        calls.append(future)
        return future

    client.call_async = call_async


def timer_runs(node: Node, executor: Executor, seconds: float) -> dict[str, int]:
    """Spin ``node`` alone on ``executor`` for ``seconds`` of wall-clock time; count its timers.

    The node is added to the executor once its service clients have found their servers,
    spun in a thread of its own, then removed, once the callbacks still running in the
    executor's threads have returned; the executor is shut down at the end, so hand over a
    fresh one each time.  A call still waiting for its answer then ends unanswered: on a
    ``SingleThreadedExecutor``, a callback that waits for a service's answer waits for ever,
    since the executor that would take the answer is the one waiting.  The node itself is
    left to the caller.

    Introduced in ``06-five-promises.ipynb``.

    :param node: a node on the wall clock (not handed to :func:`ros2nb.add`).
    :param executor: e.g. ``SingleThreadedExecutor()`` or ``MultiThreadedExecutor()``.
    :param seconds: wall-clock seconds to spin.
    :return: ``{callback name: times it ran}`` for each timer of the node.
    """
    counts: dict[str, int] = {}
    running = _Running()
    calls: list[Any] = []
    for timer in node.timers:
        _counted(timer, counts, running)
    for client in node.clients:
        track_calls(client, calls)
        client.wait_for_service(timeout_sec=SERVICE_WAIT_S)
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            executor.spin_once(timeout_sec=SPIN_WAIT_S)

    thread = threading.Thread(target=spin, name='ros2nb-timer-runs', daemon=True)
    executor.add_node(node)
    thread.start()
    try:
        time.sleep(seconds)
        measured = dict(counts)
    finally:
        stop.set()
        for future in calls:
            future.cancel()  # a callback that waits for it returns
        thread.join(FINISH_WAIT_S)
        executor.remove_node(node)
        with running.changed:  # rclpy's shutdown() does not wait for them in Jazzy
            running.changed.wait_for(lambda: running.count == 0, FINISH_WAIT_S)
        executor.shutdown()
    return measured


def callback_groups(node: Node) -> list[tuple[str, str, int]]:
    """Each timer's callback name, its callback group's type and the group's identity.

    Introduced in ``06-five-promises.ipynb``.

    :return: ``(callback name, group class name, group number)``, groups numbered from 0
        in order of first use (two timers with the same number share a group).
    """
    numbers: dict[int, int] = {}
    found = []
    for timer in node.timers:
        group = timer.callback_group
        number = numbers.setdefault(id(group), len(numbers))
        found.append((getattr(timer.callback, '__name__', repr(timer.callback)),
                      type(group).__name__, number))
    return found
