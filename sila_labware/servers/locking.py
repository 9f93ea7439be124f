"""LockController (SiLA core, the definition sila2 ships) on our servers: one client may lock a server.

Why not sila2's default implementation (`sila2.server.default_feature_implementations`): it lists
every feature as affected by the LockIdentifier metadata at all times, so every call without the
metadata is refused even while nobody holds a lock; its interceptor reads the token of a lock that
may not exist; it never records use (so the lock expires a fixed time after LockServer, however
busy its holder), and a Timeout of 0, which the standard defines as "no timeout", expires at once.

What a client sees here:
- Unlocked: every call works, with or without the metadata (a token sent anyway is ignored).
- Locked: every call to a protected feature (all but SiLAService and LockController) must carry the
  LockIdentifier metadata. Without it, sila2 refuses the call with the framework error
  InvalidMetadata; with a wrong token, the call is refused with the defined error
  InvalidLockIdentifier. Both answer the initiating call, observable commands included (below).
- Every call with the right token restarts the timeout; after `Timeout` seconds without one the
  lock lapses and the server is free. Unlock needs the token (InvalidLockIdentifier otherwise).

Refusing observable commands at initiation: sila2 runs metadata interceptors inside the execution,
after the initiating call already returned an execution UUID, so a wrong token would only surface
as the execution's error (and a sila2 client, which does not expect metadata errors there, turns it
into an undefined error). `LockGuard` therefore checks the token in a gRPC server interceptor,
before sila2's handler runs (`grpc_interceptors` puts it there). sila2's metadata interceptor
stays as a second check.

Threads: gRPC handler threads call everything here; one lock guards the lock state.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import grpc
from sila2.features.lockcontroller import (
    InvalidLockIdentifier,
    LockControllerBase,
    LockControllerFeature,
    LockServer_Responses,
    ServerAlreadyLocked,
    ServerNotLocked,
    UnlockServer_Responses,
)
from sila2.framework import Feature
from sila2.framework.fully_qualified_identifier import FullyQualifiedIdentifier
from sila2.framework.utils import raise_as_rpc_error
from sila2.server import MetadataDict, MetadataInterceptor, SilaServer

from sila_labware.device.errors import ParameterError
from sila_labware.servers.sila_glue import validation_error

logger = logging.getLogger(__name__)

UNPROTECTED_FEATURES = frozenset({"SiLAService", "LockController"})
"""Features callable without the lock token even while the server is locked (the standard's rule)."""

LOCK_IDENTIFIER = LockControllerFeature["LockIdentifier"]
_LOCK_HEADER = LOCK_IDENTIFIER.to_grpc_header_key()
# gRPC methods of a feature's service that are not calls of their own: they follow up an observable
# command by its execution UUID, or ask which calls a metadata affects; none carries metadata.
_FOLLOW_UP_SUFFIXES = ("_Info", "_Intermediate", "_Result")
_FOLLOW_UP_PREFIXES = ("Get_FCPAffectedByMetadata_",)


@dataclass
class _Held:
    token: str
    timeout_s: float  # 0: never lapses
    last_use: float  # time.monotonic() of LockServer or the last call with the token

    def lapsed(self, now: float) -> bool:
        return self.timeout_s > 0 and now - self.last_use > self.timeout_s


class ServerLock:
    """The lock state of one server: who holds it (a token) and until when; thread-safe."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._mutex = threading.Lock()
        self._held: _Held | None = None

    @property
    def locked(self) -> bool:
        with self._mutex:
            return self._current() is not None

    def lock(self, token: str, timeout_s: float) -> None:
        """Raises ServerAlreadyLocked while a lock is held (by anyone, this token included)."""
        with self._mutex:
            if self._current() is not None:
                raise ServerAlreadyLocked(
                    "The server is already locked; it must be unlocked (or time out) first"
                )
            self._held = _Held(token, timeout_s, self._clock())

    def unlock(self, token: str) -> None:
        """Raises ServerNotLocked when no lock is held, InvalidLockIdentifier for another token."""
        with self._mutex:
            held = self._current()
            if held is None:
                raise ServerNotLocked("The server is not locked")
            if token != held.token:
                raise InvalidLockIdentifier("This is not the lock identifier the server was locked with")
            self._held = None

    def admit(self, token: str) -> None:
        """A protected call with `token`: refused (InvalidLockIdentifier) unless the server is unlocked
        or locked with this token; an admitted call with the token restarts the timeout."""
        with self._mutex:
            held = self._current()
            if held is None:
                return
            if token != held.token:
                raise InvalidLockIdentifier("The server is locked with another lock identifier")
            held.last_use = self._clock()

    def _current(self) -> _Held | None:
        if self._held is not None and self._held.lapsed(self._clock()):
            logger.info("the server lock lapsed after %.0f s without a call", self._held.timeout_s)
            self._held = None
        return self._held


class LockControllerImpl(LockControllerBase):
    """LockController backed by a `ServerLock`; protection applies only while the server is locked."""

    def __init__(self, parent_server: SilaServer, lock: ServerLock | None = None) -> None:
        super().__init__(parent_server=parent_server)
        self.lock = lock if lock is not None else ServerLock()

    def get_IsLocked(self, *, metadata: MetadataDict) -> bool:
        return self.lock.locked

    def LockServer(
        self, LockIdentifier: str, Timeout: int, *, metadata: MetadataDict
    ) -> LockServer_Responses:
        if Timeout < 0:
            raise validation_error(
                LockControllerFeature,
                "LockServer",
                ParameterError(
                    "Timeout", f"Timeout must be 0 (no timeout) or a number of seconds, not {Timeout}"
                ),
            )
        self.lock.lock(LockIdentifier, float(Timeout))
        return LockServer_Responses()

    def UnlockServer(self, LockIdentifier: str, *, metadata: MetadataDict) -> UnlockServer_Responses:
        self.lock.unlock(LockIdentifier)
        return UnlockServer_Responses()

    def get_calls_affected_by_LockIdentifier(self) -> list[Feature | FullyQualifiedIdentifier]:
        """While locked: every protected feature (sila2 then requires the metadata on their calls);
        while unlocked: nothing, so clients that never lock are not asked for a token."""
        if not self.lock.locked:
            return []
        return [
            feature
            for feature in self.parent_server.features.values()
            if feature._identifier not in UNPROTECTED_FEATURES
        ]


class _LockMetadataInterceptor(MetadataInterceptor):
    """sila2's own hook (runs inside the call, for observable commands inside the execution)."""

    def __init__(self, lock: ServerLock) -> None:
        super().__init__([LOCK_IDENTIFIER])
        self.lock = lock

    def intercept(
        self, parameters: Any, metadata: MetadataDict, target_call: FullyQualifiedIdentifier
    ) -> None:
        self.lock.admit(metadata[LOCK_IDENTIFIER])


class LockGuard(grpc.ServerInterceptor):
    """Checks the lock token of protected calls before sila2 handles them (see the module docstring)."""

    def __init__(self, server: SilaServer, lock: ServerLock) -> None:
        self._server = server
        self._lock = lock

    def intercept_service(
        self, continuation: Callable[[Any], Any], handler_call_details: grpc.HandlerCallDetails
    ) -> Any:
        handler = continuation(handler_call_details)
        if handler is None or not self._is_protected(handler_call_details.method):
            return handler
        if handler.unary_unary is not None:
            return handler._replace(unary_unary=self._guard_unary(handler.unary_unary))
        if handler.unary_stream is not None:
            return handler._replace(unary_stream=self._guard_stream(handler.unary_stream))
        return handler  # SiLA has no client-streaming calls

    def _is_protected(self, method: str) -> bool:
        """`method` is '/<package>.<FeatureIdentifier>/<rpc>'."""
        service, _, rpc = method.lstrip("/").partition("/")
        feature_identifier = service.rpartition(".")[2]
        if feature_identifier in UNPROTECTED_FEATURES or feature_identifier not in self._server.features:
            return False  # binary transfer services are not features
        return not rpc.endswith(_FOLLOW_UP_SUFFIXES) and not rpc.startswith(_FOLLOW_UP_PREFIXES)

    def _admit(self, context: grpc.ServicerContext) -> None:
        """Refuse a wrong token; a missing one is left to sila2 (InvalidMetadata while locked)."""
        for key, value in context.invocation_metadata():
            if key.lower() != _LOCK_HEADER:
                continue
            try:
                token = LOCK_IDENTIFIER.to_native_type(value)
            except Exception:  # noqa: BLE001 - an undecodable value: sila2 answers InvalidMetadata
                return
            try:
                self._lock.admit(token)
            except InvalidLockIdentifier as refused:
                raise_as_rpc_error(refused, context)

    def _guard_unary(self, behaviour: Callable[[Any, grpc.ServicerContext], Any]) -> Callable[..., Any]:
        def guarded(request: Any, context: grpc.ServicerContext) -> Any:
            self._admit(context)
            return behaviour(request, context)

        return guarded

    def _guard_stream(
        self, behaviour: Callable[[Any, grpc.ServicerContext], Iterator[Any]]
    ) -> Callable[..., Any]:
        def guarded(request: Any, context: grpc.ServicerContext) -> Iterator[Any]:
            self._admit(context)
            yield from behaviour(request, context)

        return guarded


def serve_lock_controller(server: SilaServer) -> tuple[LockControllerImpl, LockGuard]:
    """Add LockController to a server that has not started; returns the implementation and the
    guard, which the server must put in front of its gRPC server (`grpc_interceptors`)."""
    if server.running:
        raise RuntimeError("LockController must be added before the server starts")
    implementation = LockControllerImpl(server)
    server.set_feature_implementation(LockControllerFeature, implementation)
    server.add_metadata_interceptor(_LockMetadataInterceptor(implementation.lock))
    return implementation, LockGuard(server, implementation.lock)
