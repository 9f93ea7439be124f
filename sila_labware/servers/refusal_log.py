"""One WARNING line per refused call in the server log; tracebacks only for undefined errors.

Why: sila2 logs every error it sends to a client with `logger.exception`, so each refused input
(a validation error, a defined execution error such as InvalidCommandSequence, a framework error
such as a missing lock token) left an ERROR-level traceback in the serve log: 1,138 lines after 25
bad inputs, which buried the one real fault among them. A refusal is the device doing its job;
an undefined error is a fault worth a traceback.

`RefusalLogFilter` sits on the log handlers (sila2 logs under names of its own, such as the
feature identifier or "observable-command-manager-<command>-<uuid>", so a filter on one logger
would miss most records) and rewrites such records in place: level WARNING, no traceback, the
command (where the logger or the error names it) and the error's own words. sila2 logs one
refused observable command twice (when it ends, and when the client fetches the result): the
second record of the same error is dropped, and so is its record without the error (sila2
writes "NoneType: None" for a command that failed at once). Records without a SiLA error, and
undefined execution errors, pass unchanged. Safe on any thread.
"""

from __future__ import annotations

import logging
import re
import threading
from collections import deque

from sila2.framework import DefinedExecutionError, FrameworkError, ValidationError

_COMMAND_IN_LOGGER = re.compile(r"/Command/(\w+)")
_COMMAND_MANAGER = "observable-command-manager-"
_FINISHED_WITH_ERROR = "Command finished with error"
_REFUSALS = (ValidationError, DefinedExecutionError, FrameworkError)


def describe_refusal(error: BaseException, logger_name: str = "") -> str:
    """'GetLabware refused: InvalidCommandSequence: ...' from a SiLA error and where it was logged."""
    where = _COMMAND_IN_LOGGER.search(logger_name)
    parameter = getattr(error, "parameter_fully_qualified_identifier", None) or ""
    where = where or _COMMAND_IN_LOGGER.search(parameter)
    command = where.group(1) if where else logger_name or "a call"
    kind = getattr(error, "identifier", "") or type(error).__name__
    detail = f" ({parameter.rsplit('/', 1)[-1]})" if parameter else ""
    return f"{command} refused: {kind}{detail}: {getattr(error, 'message', '') or error}"


class RefusalLogFilter(logging.Filter):
    """Turns sila2's traceback for a refused call into one WARNING line (see the module docstring)."""

    def __init__(self) -> None:
        super().__init__()
        self._lock = threading.Lock()
        self._recent: deque[BaseException] = deque(maxlen=64)  # held, so identities stay unique

    def filter(self, record: logging.LogRecord) -> bool:
        error = record.exc_info[1] if record.exc_info else None
        if error is None and record.name.startswith(_COMMAND_MANAGER) and record.msg == _FINISHED_WITH_ERROR:
            # sila2 logs this outside the except block when a command failed at once: no error to
            # name ("NoneType: None"). The error is logged when the client fetches the result.
            return False
        if isinstance(error, _REFUSALS):
            with self._lock:
                if any(seen is error for seen in self._recent):
                    return False
                self._recent.append(error)
            record.msg, record.args = describe_refusal(error, record.name), ()
            record.levelno, record.levelname = logging.WARNING, logging.getLevelName(logging.WARNING)
            record.exc_info, record.exc_text = None, None
        return True


def install_refusal_log_filter(logger: logging.Logger | None = None) -> None:
    """Put the filter on every handler of `logger` (default: the root logger), once."""
    for handler in (logger or logging.getLogger()).handlers:
        if not any(isinstance(existing, RefusalLogFilter) for existing in handler.filters):
            handler.addFilter(RefusalLogFilter())
