"""Results of finished observable commands kept for their lifetime by one thread, not one each.

Why: sila2 keeps a finished observable command's result for its lifetime of execution so that a
client can still fetch it, and waits out that lifetime in a thread of its own per command (it
sleeps in 1 s steps until the lifetime has passed). A transfer runs 8 such commands, so a busy
server held thousands of sleeping threads (1,098 after 131 transfers in one soak). Here the
commands are given no lifetime for sila2 to wait out (sila2 then starts no such thread and keeps
the result), and one thread per server forgets finished commands once `COMMAND_LIFETIME` has
passed since they started: the same results for the same time, with one thread.

A client is not told the lifetime on initiation (the standard makes it optional); it can fetch a
result for `COMMAND_LIFETIME` after the command started, after which the execution UUID is
unknown (InvalidCommandExecutionUUID), as it was before.

Threads: the reaper's own thread reads and prunes sila2's per-feature dictionaries of command
managers; sila2's handler threads add to them. A dictionary is pruned by key, on a snapshot of its
items, which tolerates entries added meanwhile.
"""

from __future__ import annotations

import datetime
import logging
import threading

from sila2.server import SilaServer

logger = logging.getLogger(__name__)

COMMAND_LIFETIME = datetime.timedelta(minutes=10)
"""How long a finished observable command's result stays available to clients, from its start."""
SWEEP_PERIOD_S = 5.0


class FinishedCommandReaper:
    """Forgets the finished observable commands of one server after their lifetime."""

    def __init__(
        self,
        server: SilaServer,
        lifetime: datetime.timedelta = COMMAND_LIFETIME,
        period_s: float = SWEEP_PERIOD_S,
    ) -> None:
        self._server = server
        self.lifetime = lifetime
        self._period_s = period_s
        self._stopped = threading.Event()
        self._thread = threading.Thread(
            target=self._run, name=f"finished-commands-{server.server_uuid}", daemon=True
        )

    def start(self) -> FinishedCommandReaper:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stopped.set()
        if self._thread.is_alive():
            self._thread.join(timeout=self._period_s + 1.0)

    def sweep(self) -> int:
        """Forget every finished command older than the lifetime; returns how many."""
        now = datetime.datetime.now()
        forgotten = 0
        for servicer in list(self._server.feature_servicers.values()):
            for managers in list(getattr(servicer, "observable_command_managers", {}).values()):
                for execution_uuid, manager in list(managers.items()):
                    if not manager.is_running() and now - manager.execution_start_time > self.lifetime:
                        managers.pop(execution_uuid, None)
                        forgotten += 1
        return forgotten

    def _run(self) -> None:
        while not self._stopped.wait(self._period_s):
            try:
                forgotten = self.sweep()
            except Exception:  # noqa: BLE001 - the sweep must go on; the next one retries
                logger.exception("forgetting finished commands failed")
                continue
            if forgotten:
                logger.debug("forgot %d finished commands", forgotten)
