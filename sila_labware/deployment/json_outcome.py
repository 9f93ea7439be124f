"""One JSON object on stdout for every machine-readable run, whatever happens.

Why: a pipeline that asked for JSON (`demo --json`, `bench --json`, `serve --print-config json`)
parses stdout. A run refused before its command started (a bad option, a missing or invalid world
file), one whose robot side could not start, one stopped by a signal and one that crashed must
still give it exactly one object to read. Every such object carries the same four fields, so a
script can branch on them without knowing the command:

    success     true only if the command did what it was asked
    error       "" on success, else the reason in one sentence (the line also written to stderr)
    error_kind  "" on success, else one of ERROR_KINDS (stable: scripts may switch on it)
    exit_code   the process's exit code (null in `serve`'s connection document: it still runs)

Threads: the CLI's main thread only (one object per process; `reset` starts over, for tests
that call `main` more than once in one process).
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from typing import Any, TextIO

USAGE = "usage"  # exit 2: bad options or arguments, a missing or invalid world file
START_FAILED = "start_failed"  # exit 1: the robot side or the servers could not start
FAILED = "failed"  # exit 1: the command ran and did not succeed (the plate not delivered, a trial failed)
INTERRUPTED = "interrupted"  # exit 130: SIGINT or SIGTERM
INTERNAL = "internal"  # exit 1: an unexpected error (a bug): the traceback is on stderr
ERROR_KINDS = (USAGE, START_FAILED, FAILED, INTERRUPTED, INTERNAL)

_JSON_FLAG = "--json"
_CONFIG_FLAG = "--print-config"


class UsageError(SystemExit):
    """Bad usage (exit 2); the one-line message has been written to stderr already."""

    def __init__(self, message: str) -> None:
        super().__init__(2)
        self.message = message


def json_requested(argv: Sequence[str]) -> bool:
    """Whether the command line asks for JSON on stdout: `--json` or `--print-config` (argparse's
    abbreviations and `--flag=value` forms included), before `--`, whatever else is wrong with it."""
    for token in argv:
        if token == "--":
            return False
        flag = token.split("=", 1)[0]
        if len(flag) >= 3 and _JSON_FLAG.startswith(flag):
            return True
        if len(flag) >= 4 and _CONFIG_FLAG.startswith(flag):
            return True
    return False


def outcome_fields(error: str = "", error_kind: str = "", exit_code: int | None = 0) -> dict[str, Any]:
    """The four fields every JSON object carries (see the module docstring)."""
    if error_kind and error_kind not in ERROR_KINDS:
        raise ValueError(f"unknown error kind {error_kind!r}; expected one of {', '.join(ERROR_KINDS)}")
    if bool(error) != bool(error_kind):
        raise ValueError("an error needs its kind and a kind its error")
    return {"success": not error, "error": error, "error_kind": error_kind, "exit_code": exit_code}


class JsonOutput:
    """Remembers whether this process has written its object, so a failure after it adds none."""

    written = False

    @classmethod
    def write(cls, document: dict[str, Any], stream: TextIO | None = None) -> None:
        """The object on one line, flushed (a reader may wait for it line by line)."""
        target = sys.stdout if stream is None else stream
        target.write(json.dumps(document) + "\n")
        target.flush()
        cls.written = True

    @classmethod
    def write_failure(cls, error: str, error_kind: str, exit_code: int) -> None:
        """A failure's object, unless this process wrote its object already."""
        if not cls.written:
            cls.write(outcome_fields(error, error_kind, exit_code))

    @classmethod
    def reset(cls) -> None:
        cls.written = False
