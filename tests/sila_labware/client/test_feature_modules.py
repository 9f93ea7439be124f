"""A feature definition is compiled to protobuf modules once per process, whoever builds it.

Real parts: sila2's Feature and its protoc compilation of our feature definitions.
"""

from __future__ import annotations

from pathlib import Path

from sila2.framework import Feature

from sila_labware.client import feature_modules

FEATURES = Path(__file__).resolve().parents[3] / "features"


def test_the_same_definition_reuses_its_modules_and_another_compiles_its_own() -> None:
    cache = feature_modules.enable()
    assert feature_modules.enable() is cache, "enabling twice keeps one cache"
    site = (FEATURES / "LabwareTransferSiteController.sila.xml").read_text()
    before = cache.compilations
    first, second = Feature(site), Feature(site)
    assert cache.compilations - before <= 1, "the second build compiled the definition again"
    assert first._pb2_module is second._pb2_module
    request = first._pb2_module.LabwareDelivered_Parameters  # the compiled messages work
    assert request.DESCRIPTOR.full_name.endswith("LabwareDelivered_Parameters")
    other = Feature((FEATURES / "CancelController.sila.xml").read_text())
    assert other._pb2_module is not first._pb2_module
