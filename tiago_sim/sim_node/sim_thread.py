"""The one thread that owns PyBullet: steps the Simulation and runs jobs handed to it.

PyBullet is not thread-safe, so every call into the Simulation happens on this thread. ROS
callbacks (other threads) submit jobs with `call(fn)` and wait on the returned future. The
thread steps as fast as it may while a Motion runs (optionally capped at a real-time factor)
and throttles to `idle_realtime_factor` while idle, so an idle node does not burn a core.
"""

from __future__ import annotations

import cProfile
import logging
import os
import queue
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any, TypeVar

log = logging.getLogger(__name__)

T = TypeVar("T")

# Set to a file path to write a cProfile of the sim thread there when it stops (profiling runs only).
PROFILE_ENV = "TIAGO_SIM_PROFILE"

# While busy, run queued jobs after at most this many steps so ROS callbacks stay responsive.
_STEPS_BETWEEN_JOB_CHECKS = 24


class SimThread:
    """Owns a Simulation built by `factory` on its own thread (lives on: the sim thread)."""

    def __init__(
        self,
        factory: Callable[[], Any],
        *,
        realtime_factor_cap: float | None = None,
        idle_realtime_factor: float = 1.0,
    ) -> None:
        self._factory = factory
        self._jobs: queue.SimpleQueue[tuple[Callable[[Any], Any], Future]] = queue.SimpleQueue()
        self._stop = threading.Event()
        # Set by call() and stop(): a thread pacing an idle robot wakes for a new job at once.
        self._wake = threading.Event()
        self._ready: Future = Future()
        self._replacement: Any = None  # a rebuilt Simulation the loop takes over (see rebuild)
        # Checks that must see every batch of steps (not a wall-clock sample of them); sim thread only.
        self._watchers: list[Callable[[Any], bool]] = []
        self.realtime_factor_cap = realtime_factor_cap
        self.idle_realtime_factor = idle_realtime_factor
        self.sim_time = 0.0  # copy of sim.sim_time, readable from any thread
        self.steps = 0
        # CPU accounting (load-independent speed): sim seconds advanced while a Motion ran, the
        # thread's CPU seconds for them, and CPU seconds spent in jobs (IK, rendering, snapshots).
        self.busy_sim_s = 0.0
        self.in_motion = False  # a motion ran at the last batch of steps (a plain flag other threads read)
        self.busy_cpu_s = 0.0
        self.job_cpu_s = 0.0
        self._thread = threading.Thread(target=self._run_maybe_profiled, name="sim", daemon=True)

    def start(self, timeout_s: float = 60.0) -> None:
        """Start the thread and wait until the Simulation is built (raises its error if not)."""
        self._thread.start()
        self._ready.result(timeout=timeout_s)

    @property
    def stopped(self) -> bool:
        return self._stop.is_set()

    def stop(self, timeout_s: float = 5.0) -> None:
        self._stop.set()
        self._wake.set()
        self._thread.join(timeout=timeout_s)

    def call(self, job: Callable[[Any], T]) -> Future:
        """Run `job(sim)` on the sim thread; the future holds its return value or exception."""
        future: Future = Future()
        if self._stop.is_set():
            future.set_exception(RuntimeError("simulation stopped"))
            return future
        self._jobs.put((job, future))
        self._wake.set()
        return future

    def run(self, job: Callable[[Any], T], timeout_s: float = 30.0) -> T:
        """`call` and wait for the result."""
        return self.call(job).result(timeout=timeout_s)

    def rebuild(self, timeout_s: float = 30.0) -> float:
        """Build the Simulation anew from its factory, in place of the running one (a lab reset:
        plates, robot and disturbances as at start, no process restarted). Its clock goes on from
        the old one's, so /clock never runs backwards; watchers end. Returns the sim time it
        resumed at. Callers make sure no goal runs (the action servers' motion slot)."""

        def replace(old: Any) -> float:
            new = self._factory()
            new.sim_time = old.sim_time
            self._watchers = []
            close = getattr(old, "close", None)
            if callable(close):
                close()
            self._replacement = new
            return float(new.sim_time)

        return self.run(replace, timeout_s)

    def watch(self, watcher: Callable[[Any], bool]) -> None:
        """Run `watcher(sim)` on the sim thread after every batch of steps (at most
        _STEPS_BETWEEN_JOB_CHECKS steps apart, whatever the load) until it returns True."""
        self.call(lambda _sim: self._watchers.append(watcher))

    def _run_watchers(self, sim: Any) -> None:
        self._watchers = [watcher for watcher in self._watchers if not watcher(sim)]

    def _run_jobs(self, sim: Any) -> None:
        while True:
            try:
                job, future = self._jobs.get_nowait()
            except queue.Empty:
                return
            if not future.set_running_or_notify_cancel():
                continue
            try:
                future.set_result(job(sim))
            except BaseException as error:  # noqa: BLE001 - handed to the waiting thread
                future.set_exception(error)
            if self._replacement is not None:
                return  # the jobs after a rebuild act on the new Simulation

    def _run_maybe_profiled(self) -> None:
        profile_path = os.environ.get(PROFILE_ENV)
        if not profile_path:
            self._run()
            return
        profiler = cProfile.Profile()
        profiler.enable()
        try:
            self._run()
        finally:
            profiler.disable()
            profiler.dump_stats(profile_path)
            log.info("sim thread profile written to %s", profile_path)

    def _run(self) -> None:
        try:
            sim = self._factory()
        except BaseException as error:  # noqa: BLE001 - reported to start()
            log.exception("building the simulation failed")
            self._ready.set_exception(error)
            return
        self._ready.set_result(True)
        wall_start, sim_start = time.monotonic(), sim.sim_time
        paced_factor: float | None = None

        def ahead_of_wall_s(factor: float) -> float:
            """How far the sim clock runs ahead of the wall clock at this pace (negative: behind)."""
            return (sim.sim_time - sim_start) / factor - (time.monotonic() - wall_start)

        try:
            while not self._stop.is_set():
                cpu_before = time.thread_time()
                self._wake.clear()  # before draining: a job queued from here on sets it again
                # Watchers first: they react to the last batch of steps (a fault that fires on a
                # release) before a job reads the sensors, or a report could show the moment between.
                if self._watchers:
                    self._run_watchers(sim)
                self._run_jobs(sim)
                if self._replacement is not None:
                    sim, self._replacement = self._replacement, None
                    wall_start, sim_start, paced_factor = time.monotonic(), sim.sim_time, None
                cpu_after_jobs = time.thread_time()
                self.job_cpu_s += cpu_after_jobs - cpu_before
                busy = self.in_motion = sim.busy()
                factor = self.realtime_factor_cap if busy else self.idle_realtime_factor
                if factor == paced_factor and factor is not None and factor > 0:
                    ahead_s = ahead_of_wall_s(factor)
                    if ahead_s > 0:
                        # Woken for a job while the clock is ahead of the wall: no step, or every
                        # job would advance the clock on top of the wall time it took (idle: about
                        # 1 s a transfer; in motion a whole batch of steps per job, which ran a
                        # motion capped at 1x real time at several times real time).
                        self._wake.wait(min(ahead_s, 0.05))
                        continue
                if busy:
                    for _ in range(_STEPS_BETWEEN_JOB_CHECKS):
                        sim.step()
                        self.steps += 1
                        if not sim.busy():
                            break
                    self.busy_sim_s += sim.sim_time - self.sim_time
                    self.busy_cpu_s += time.thread_time() - cpu_after_jobs
                    self.sim_time = sim.sim_time
                else:
                    sim.step()
                    self.steps += 1
                    self.sim_time = sim.sim_time
                if factor is None or factor <= 0 or factor != paced_factor:
                    # Unpaced, or the pace changed: measure from here.
                    wall_start, sim_start = time.monotonic(), sim.sim_time
                    paced_factor = factor
                    continue
                # Sleep until wall time catches up with sim time at the chosen factor.
                ahead_s = ahead_of_wall_s(factor)
                if ahead_s > 0:
                    self._wake.wait(min(ahead_s, 0.05))
                elif ahead_s < -0.5:  # fell behind (busy phases): do not try to catch up later
                    wall_start, sim_start = time.monotonic(), sim.sim_time
        finally:
            log.info(
                "sim thread: %.1f s simulated in motion for %.2f s CPU (%.1fx real time per core), "
                "%.2f s CPU in jobs, %.1f s simulated in all; the whole process used %.2f s CPU",
                self.busy_sim_s,
                self.busy_cpu_s,
                self.busy_sim_s / self.busy_cpu_s if self.busy_cpu_s > 0 else 0.0,
                self.job_cpu_s,
                sim.sim_time,
                time.process_time(),
            )
            ledger = getattr(sim, "step_ledger", None)
            if ledger is not None:
                log.info("physics steps by regime: %s", ledger.summary())
            self._drain_after_stop()
            close = getattr(sim, "close", None)
            if callable(close):
                try:
                    close()
                except Exception:  # noqa: BLE001 - shutting down anyway
                    log.debug("closing the simulation failed", exc_info=True)

    def _drain_after_stop(self) -> None:
        while True:
            try:
                _, future = self._jobs.get_nowait()
            except queue.Empty:
                return
            if future.set_running_or_notify_cancel():
                future.set_exception(RuntimeError("simulation stopped"))
