"""The pid of the process that started this one, noted before anything slow is imported.

Why: a robot-side node stops once its starter is gone (`node_main`). Read after rclpy and the
world had loaded, a starter killed in those seconds (a busy machine makes them many) was already
replaced by init, and the orphaned node never noticed. The `__main__` modules call
`note_starter` first; a child forked from the prewarmed server runs it after its re-parenting.
"""

import os

_starter_pid: int | None = None


def note_starter() -> None:
    """Remember this process's parent now, as the process that started it."""
    global _starter_pid
    _starter_pid = os.getppid()


def starter_pid() -> int:
    """The noted starter, or the parent now when nothing was noted (a node started from a test)."""
    return _starter_pid if _starter_pid is not None else os.getppid()
