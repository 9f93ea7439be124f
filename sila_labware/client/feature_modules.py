"""Compile each SiLA feature definition to Python protobuf modules once per process.

Why: sila2's client builds every feature a server lists from its definition (XML -> .proto by
XSLT -> protoc -> import), at every connection: about 20 ms per feature, some 30 features a
transfer client (robot and two stations). A campaign connects a fresh client every trial, and
that compilation was half of its own process's CPU per trial. The modules depend on the
definition alone, so a definition seen before reuses its modules; message and stub classes are
read-only to sila2 (a server subclasses the servicer, it never changes it).

This wraps one function of sila2 (`sila2.framework.feature.feature_definition_to_modules`, sila2
0.14); `enable` refuses to run against a sila2 that lacks it rather than quietly compiling again.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from types import ModuleType
from typing import Any

import sila2.framework.feature as sila_feature
from sila2.framework.utils import xml_node_to_normalized_string

logger = logging.getLogger(__name__)

Compiler = Callable[[Any], tuple[ModuleType, ModuleType]]


class CompiledFeatures:
    """Modules by canonical feature definition (XML C14N 2.0 without whitespace)."""

    def __init__(self, compile_modules: Compiler) -> None:
        self.compile_modules = compile_modules
        self.modules: dict[str, tuple[ModuleType, ModuleType]] = {}
        self.compilations = 0
        self._lock = threading.Lock()  # protoc and sila2's sys.path juggling are not thread-safe

    def __call__(self, fdl_node: Any) -> tuple[ModuleType, ModuleType]:
        key = xml_node_to_normalized_string(fdl_node)
        with self._lock:
            if key not in self.modules:
                self.modules[key] = self.compile_modules(fdl_node)
                self.compilations += 1
            return self.modules[key]


def enable() -> CompiledFeatures:
    """Install the cache in sila2 (once; later calls return the installed one)."""
    current = getattr(sila_feature, "feature_definition_to_modules", None)
    if isinstance(current, CompiledFeatures):
        return current
    if current is None:
        raise RuntimeError("sila2.framework.feature has no feature_definition_to_modules to cache")
    cache = CompiledFeatures(current)
    sila_feature.feature_definition_to_modules = cache
    logger.debug("SiLA feature modules are compiled once per process")
    return cache
