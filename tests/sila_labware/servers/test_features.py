"""Feature definitions: schema-valid, and the standard ones wire-compatible with the published standard.

Why: a scheduler written against the SiLA labware transfer standard must talk to our robot unchanged.
That holds only if the gRPC interface generated from our definition is the same as the one generated
from the standard's own definition (shipped in the unitelabs-cdk wheel), and if identifiers, order,
errors and constraints (which the proto does not carry) agree too. Descriptions are ours and may differ.
The same holds for the SiLA core features we define ourselves: SimulationController (compared with the
file in unitelabs-cdk) and CancelController (no library ships it: compared with the standard's
elements, written out below from the SiLA base repository's definition).
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable
from pathlib import Path

import pytest
import sila2.resources
import unitelabs.cdk.features.core.simulation_controller as standard_simulation
import unitelabs.cdk.features.robot.labware_transfer_manipulator_controller as standard_manipulator
from google.protobuf import descriptor_pb2, text_format
from grpc_tools import protoc
from lxml import etree
from sila2.framework import Feature
from sila2.framework.errors.validation_error import ValidationError
from sila2.framework.utils import feature_definition_to_proto_string, parse_feature_definition

FEATURES_DIR = Path(__file__).resolve().parents[3] / "features"
SILA_RESOURCES = Path(sila2.resources.__file__).parent
STANDARD_DIR = Path(standard_manipulator.__file__).parent
STANDARD_MANIPULATOR_FDL = STANDARD_DIR / "LabwareTransferManipulatorController-v1_0.sila.xml"
STANDARD_MANIPULATOR_PROTO = STANDARD_DIR / "LabwareTransferManipulatorController-v1_0.proto"
OUR_MANIPULATOR_FDL = FEATURES_DIR / "LabwareTransferManipulatorController.sila.xml"
OUR_SITE_FDL = FEATURES_DIR / "LabwareTransferSiteController.sila.xml"
OWN_FEATURES = (
    "MobileRobotController.sila.xml",
    "LabwareInventory.sila.xml",
    "SimulatedLabController.sila.xml",
)
OUR_CANCEL_FDL = FEATURES_DIR / "CancelController.sila.xml"
OUR_SIMULATION_FDL = FEATURES_DIR / "SimulationController.sila.xml"
STANDARD_SIMULATION_FDL = Path(standard_simulation.__file__).parent / "SimulationController-v1_0.sila.xml"
SILA_NS = "http://www.sila-standard.org"
NS = {"sila": SILA_NS}


# ---------------------------------------------------------------------------------------------------------
# Helpers: schema, FDL skeleton (everything but descriptions), proto descriptors
# ---------------------------------------------------------------------------------------------------------


def schema_errors(fdl_path: Path) -> list[str]:
    """Errors of the FDL against sila2's XSD and its semantic checks (XSLT); empty if valid."""
    schema = etree.XMLSchema(etree.parse(str(SILA_RESOURCES / "xsd" / "FeatureDefinition.xsd")))
    document = etree.parse(str(fdl_path))
    if not schema.validate(document):
        return [str(error) for error in schema.error_log]
    semantic_check = etree.XSLT(etree.parse(str(SILA_RESOURCES / "xsl" / "fdl-validation.xsl")))
    try:
        semantic_check(document)
    except etree.XSLTApplyError as error:
        return [f"semantic check: {error}"]
    return []


def _local(tag: str) -> str:
    return etree.QName(tag).localname


def skeleton_lines(element: etree._Element, path: str = "") -> list[str]:
    """One line per element: path, attributes and text, with Description elements left out.

    Identifiers, display names, types, constraints, order and errors all end up in these lines, so two
    definitions whose skeletons are equal differ in their prose only.
    """
    label = _local(element.tag)
    identifier = element.find("sila:Identifier", NS)
    if identifier is not None and label != "DefinedExecutionErrors":
        label += f"[{identifier.text.strip()}]"
    here = f"{path}/{label}"
    attributes = " ".join(
        f"{_local(key)}={value}"
        for key, value in sorted(element.attrib.items())
        if _local(key) != "schemaLocation"
    )
    text = (element.text or "").strip()
    lines = [f"{here} [{attributes}] {text!r}"]
    for child in element:
        if isinstance(child, etree._Comment) or _local(child.tag) == "Description":
            continue
        lines += skeleton_lines(child, here)
    return lines


def fdl_skeleton(fdl_path: Path) -> list[str]:
    return skeleton_lines(etree.parse(str(fdl_path)).getroot())


def skeleton_diff(expected: list[str], actual: list[str]) -> list[str]:
    return [
        line
        for line in difflib.unified_diff(expected, actual, "standard", "ours", lineterm="", n=0)
        if line.startswith(("+", "-")) and not line.startswith(("+++", "---"))
    ]


def compile_proto(proto_file: Path, out_dir: Path) -> descriptor_pb2.FileDescriptorProto:
    """Compile with protoc (grpcio-tools) and return the parsed descriptor of this file, name cleared."""
    descriptor_set_path = out_dir / f"{proto_file.stem}.pb"
    exit_code = protoc.main(
        [
            "protoc",
            f"--proto_path={proto_file.parent}",
            f"--proto_path={SILA_RESOURCES / 'proto'}",
            f"--descriptor_set_out={descriptor_set_path}",
            str(proto_file),
        ]
    )
    assert exit_code == 0, f"protoc failed on {proto_file}"
    descriptor_set = descriptor_pb2.FileDescriptorSet.FromString(descriptor_set_path.read_bytes())
    (file_descriptor,) = [f for f in descriptor_set.file if f.name == proto_file.name]
    file_descriptor.ClearField("name")
    return file_descriptor


def proto_from_fdl(fdl_path: Path, out_dir: Path) -> descriptor_pb2.FileDescriptorProto:
    """The feature's gRPC interface exactly as sila2 derives it (its own FDL-to-proto XSLT), compiled."""
    out_dir.mkdir(parents=True, exist_ok=True)
    fdl_root = parse_feature_definition(str(fdl_path))
    feature_id = fdl_root.find("sila:Identifier", NS).text.strip()
    proto_file = out_dir / f"{feature_id}.proto"
    proto_file.write_text(feature_definition_to_proto_string(fdl_root), encoding="utf-8")
    return compile_proto(proto_file, out_dir)


def descriptor_entries(file_descriptor: descriptor_pb2.FileDescriptorProto) -> dict[str, tuple]:
    """Flatten messages, fields and rpc methods into comparable entries keyed by their names."""
    entries: dict[str, tuple] = {
        "package": (file_descriptor.package,),
        "imports": tuple(file_descriptor.dependency),
    }

    def add_message(message: descriptor_pb2.DescriptorProto, prefix: str) -> None:
        name = f"{prefix}{message.name}"
        entries[f"message {name}"] = (len(message.field),)
        for field in message.field:
            label = descriptor_pb2.FieldDescriptorProto.Label.Name(field.label)
            kind = descriptor_pb2.FieldDescriptorProto.Type.Name(field.type)
            entries[f"field {name}.{field.name}"] = (field.number, kind, label, field.type_name)
        for nested in message.nested_type:
            add_message(nested, f"{name}.")

    for message in file_descriptor.message_type:
        add_message(message, "")
    for service in file_descriptor.service:
        for method in service.method:
            entries[f"rpc {service.name}.{method.name}"] = (
                method.input_type,
                method.output_type,
                method.client_streaming,
                method.server_streaming,
            )
    return entries


def descriptor_differences(
    expected: descriptor_pb2.FileDescriptorProto, actual: descriptor_pb2.FileDescriptorProto
) -> list[str]:
    expected_entries, actual_entries = descriptor_entries(expected), descriptor_entries(actual)
    differences = [f"missing {key}" for key in sorted(expected_entries.keys() - actual_entries.keys())]
    differences += [f"extra {key}" for key in sorted(actual_entries.keys() - expected_entries.keys())]
    differences += [
        f"{key}: standard {expected_entries[key]} ours {actual_entries[key]}"
        for key in sorted(expected_entries.keys() & actual_entries.keys())
        if expected_entries[key] != actual_entries[key]
    ]
    if not differences and expected != actual:  # anything the flattening does not cover (options, oneofs)
        differences = list(
            difflib.unified_diff(
                text_format.MessageToString(expected).splitlines(),
                text_format.MessageToString(actual).splitlines(),
                lineterm="",
            )
        )
    return differences


# ---------------------------------------------------------------------------------------------------------
# (a) every definition is valid
# ---------------------------------------------------------------------------------------------------------


def test_features_directory_holds_the_seven_definitions() -> None:
    names = sorted(path.name for path in FEATURES_DIR.glob("*.sila.xml"))
    expected = [OUR_MANIPULATOR_FDL, OUR_SITE_FDL, OUR_CANCEL_FDL, OUR_SIMULATION_FDL]
    assert names == sorted([*(path.name for path in expected), *OWN_FEATURES]), (
        f"unexpected feature files: {names}"
    )


@pytest.mark.parametrize("fdl_path", sorted(FEATURES_DIR.glob("*.sila.xml")), ids=lambda path: path.name)
def test_feature_definition_is_schema_valid(fdl_path: Path) -> None:
    assert schema_errors(fdl_path) == []
    Feature(str(fdl_path))  # and sila2 itself loads it (compiles its proto)


def test_schema_check_rejects_an_invalid_definition(tmp_path: Path) -> None:
    broken = tmp_path / "Broken.sila.xml"
    text = OUR_MANIPULATOR_FDL.read_text(encoding="utf-8")
    broken.write_text(text.replace("<Observable>Yes</Observable>", "<Observable>Maybe</Observable>", 1))
    assert schema_errors(broken)
    undefined_error = tmp_path / "UndefinedError.sila.xml"
    undefined_error.write_text(
        text.replace(
            "<Identifier>LabwareNotPlaced</Identifier>\n    </Defined",
            "<Identifier>Nope</Identifier>\n    </Defined",
            1,
        )
    )
    assert any("Nope" in error for error in schema_errors(undefined_error))


# ---------------------------------------------------------------------------------------------------------
# (b) conformance of the manipulator feature with the published standard
# ---------------------------------------------------------------------------------------------------------


def test_manipulator_proto_equals_the_standard(tmp_path: Path) -> None:
    standard = proto_from_fdl(STANDARD_MANIPULATOR_FDL, tmp_path / "standard")
    ours = proto_from_fdl(OUR_MANIPULATOR_FDL, tmp_path / "ours")
    assert descriptor_differences(standard, ours) == []
    assert standard == ours


def test_manipulator_proto_equals_the_proto_shipped_with_the_standard(tmp_path: Path) -> None:
    shipped = compile_proto(STANDARD_MANIPULATOR_PROTO, tmp_path)
    ours = proto_from_fdl(OUR_MANIPULATOR_FDL, tmp_path / "ours")
    assert descriptor_differences(shipped, ours) == []


def test_manipulator_skeleton_equals_the_standard() -> None:
    """Identifiers, display names, types, constraints, order and errors; not descriptions."""
    assert skeleton_diff(fdl_skeleton(STANDARD_MANIPULATOR_FDL), fdl_skeleton(OUR_MANIPULATOR_FDL)) == []


def descriptions(path: Path) -> set[str]:
    root = etree.parse(str(path)).getroot()
    return {" ".join(node.text.split()) for node in root.iter(f"{{{SILA_NS}}}Description")}


def test_manipulator_descriptions_are_our_own() -> None:
    assert descriptions(STANDARD_MANIPULATOR_FDL).isdisjoint(descriptions(OUR_MANIPULATOR_FDL))


def _find(root: etree._Element, xpath: str) -> etree._Element:
    (node,) = root.xpath(xpath, namespaces=NS)
    return node


def _swap_labware_parameters(root: etree._Element) -> None:
    labware_type = _find(
        root, "sila:Command[sila:Identifier='PrepareForInput']/sila:Parameter[sila:Identifier='LabwareType']"
    )
    labware_type.addprevious(labware_type.getnext())  # LabwareUniqueID now comes first


def _rename_internal_position(root: etree._Element) -> None:
    _find(
        root,
        "sila:Command[sila:Identifier='PrepareForOutput']/sila:Parameter/sila:Identifier[.='InternalPosition']",
    ).text = "Slot"


def _labware_type_as_integer(root: etree._Element) -> None:
    _find(
        root,
        "sila:Command[sila:Identifier='PrepareForInput']/sila:Parameter[sila:Identifier='LabwareType']//sila:Basic",
    ).text = "Integer"


def _put_labware_unobservable(root: etree._Element) -> None:
    _find(root, "sila:Command[sila:Identifier='PutLabware']/sila:Observable").text = "No"


def _position_index_bound_changed(root: etree._Element) -> None:
    bound = _find(root, "sila:DataTypeDefinition[sila:Identifier='PositionIndex']//sila:MinimalInclusive")
    bound.text = "0"


def _error_renamed(root: etree._Element) -> None:
    for identifier in root.xpath("//sila:Identifier[.='LabwareNotPlaced']", namespaces=NS):
        identifier.text = "LabwareNotDropped"


# mutation -> (altered definition, caught by the proto comparison, caught by the skeleton comparison).
# Constraints and error identifiers do not reach the proto: only the skeleton comparison sees them.
MUTATIONS: dict[str, tuple[Callable[[etree._Element], None], bool, bool]] = {
    "parameter order swapped": (_swap_labware_parameters, True, True),
    "parameter renamed": (_rename_internal_position, True, True),
    "parameter type changed": (_labware_type_as_integer, True, True),
    "command made unobservable": (_put_labware_unobservable, True, True),
    "constraint changed": (_position_index_bound_changed, False, True),
    "error identifier changed": (_error_renamed, False, True),
}


@pytest.mark.parametrize("mutation_name", sorted(MUTATIONS))
def test_conformance_checks_catch_an_altered_copy(mutation_name: str, tmp_path: Path) -> None:
    mutate, proto_should_differ, skeleton_should_differ = MUTATIONS[mutation_name]
    document = etree.parse(str(OUR_MANIPULATOR_FDL))
    mutate(document.getroot())
    altered = tmp_path / "LabwareTransferManipulatorController.sila.xml"
    document.write(str(altered), xml_declaration=True, encoding="utf-8")
    assert schema_errors(altered) == [], "the altered copy must still be a valid definition"

    standard = proto_from_fdl(STANDARD_MANIPULATOR_FDL, tmp_path / "standard")
    altered_proto = proto_from_fdl(altered, tmp_path / "altered")
    assert bool(descriptor_differences(standard, altered_proto)) == proto_should_differ
    assert bool(skeleton_diff(fdl_skeleton(STANDARD_MANIPULATOR_FDL), fdl_skeleton(altered))) == (
        skeleton_should_differ
    )


# ---------------------------------------------------------------------------------------------------------
# The site feature: no published file; it must share every common element with the manipulator
# ---------------------------------------------------------------------------------------------------------

SHARED_WITH_MANIPULATOR = (
    "Command[PrepareForInput]",
    "Command[PrepareForOutput]",
    "Property[AvailableHandoverPositions]",
    "Property[NumberOfInternalPositions]",
    "DataTypeDefinition[HandoverPosition]",
    "DataTypeDefinition[PositionIndex]",
    "DefinedExecutionError[InvalidCommandSequence]",
)


def _element_lines(lines: list[str], element: str) -> list[str]:
    """The skeleton lines of one top-level element, without the feature's own name in front."""
    selected = []
    for line in lines:
        path, rest = line.split(" ", 1)
        inner_path = path.split("/", 2)[2] if path.count("/") >= 2 else ""
        if inner_path == element or inner_path.startswith(f"{element}/"):
            selected.append(f"{inner_path} {rest}")
    return selected


def test_site_feature_shares_the_standard_elements() -> None:
    standard, site = fdl_skeleton(STANDARD_MANIPULATOR_FDL), fdl_skeleton(OUR_SITE_FDL)
    for element in SHARED_WITH_MANIPULATOR:
        standard_lines, site_lines = _element_lines(standard, element), _element_lines(site, element)
        assert standard_lines, element
        assert skeleton_diff(standard_lines, site_lines) == [], element
    # The feature-level attributes (originator, category, versions) are those of the standard, too.
    assert site[0].split(" ", 1)[1] == standard[0].split(" ", 1)[1]


def test_site_feature_has_exactly_the_standard_commands_and_properties() -> None:
    feature = Feature(str(OUR_SITE_FDL))
    assert str(feature.fully_qualified_identifier) == (
        "org.silastandard/instruments.labware.manipulation/LabwareTransferSiteController/v1"
    )
    root = etree.parse(str(OUR_SITE_FDL)).getroot()
    commands = {
        command.findtext("sila:Identifier", namespaces=NS): (
            command.findtext("sila:Observable", namespaces=NS),
            [p.findtext("sila:Identifier", namespaces=NS) for p in command.findall("sila:Parameter", NS)],
            command.findall("sila:Response", NS),
            [e.text for e in command.findall("sila:DefinedExecutionErrors/sila:Identifier", NS)],
        )
        for command in root.findall("sila:Command", NS)
    }
    transfer = ["HandoverPosition", "InternalPosition"]
    assert commands == {
        "PrepareForInput": (
            "Yes",
            [*transfer, "LabwareType", "LabwareUniqueID"],
            [],
            ["InvalidCommandSequence"],
        ),
        "PrepareForOutput": ("Yes", transfer, [], ["InvalidCommandSequence"]),
        "LabwareDelivered": ("Yes", ["HandoverPosition"], [], ["InvalidCommandSequence"]),
        "LabwareRemoved": ("Yes", ["HandoverPosition"], [], ["InvalidCommandSequence"]),
    }
    properties = [p.findtext("sila:Identifier", namespaces=NS) for p in root.findall("sila:Property", NS)]
    assert properties == ["AvailableHandoverPositions", "NumberOfInternalPositions"]


SHARED_MESSAGES = {
    f"{element}_{kind}"
    for element in (
        "PrepareForInput",
        "PrepareForOutput",
        "Get_AvailableHandoverPositions",
        "Get_NumberOfInternalPositions",
    )
    for kind in ("Parameters", "Responses")
} | {"DataType_HandoverPosition", "DataType_PositionIndex"}


def test_site_proto_messages_match_the_standard_for_shared_commands(tmp_path: Path) -> None:
    standard = proto_from_fdl(STANDARD_MANIPULATOR_FDL, tmp_path / "standard")
    site = proto_from_fdl(OUR_SITE_FDL, tmp_path / "site")

    def shared(file_descriptor: descriptor_pb2.FileDescriptorProto) -> dict[str, tuple]:
        """Entries of the shared messages, with the feature's own package name masked."""
        package = file_descriptor.package
        return {
            key: tuple(str(value).replace(package, "<feature>") for value in values)
            for key, values in descriptor_entries(file_descriptor).items()
            if key.split(" ", 1)[0] in ("message", "field")
            and key.split(" ", 1)[1].split(".")[0] in SHARED_MESSAGES
        }

    assert len(shared(standard)) > len(SHARED_MESSAGES)  # the messages and their fields
    assert shared(site) == shared(standard)


# ---------------------------------------------------------------------------------------------------------
# Our own features: what the brief promises, and oversized strings are rejected by sila2 itself
# ---------------------------------------------------------------------------------------------------------


def _string_constraints(data_type: etree._Element, root: etree._Element) -> list[dict[str, str]] | None:
    """For a DataType: the constraints of every String it contains (None for non-string leaves)."""
    found: list[dict[str, str]] = []
    for basic in data_type.iter(f"{{{SILA_NS}}}Basic"):
        if basic.text != "String":
            continue
        constrained = basic.getparent().getparent()
        constraints = (
            {_local(c.tag): (c.text or "").strip() for c in constrained.find("sila:Constraints", NS)}
            if _local(constrained.tag) == "Constrained"
            else {}
        )
        found.append(constraints)
    for reference in data_type.iter(f"{{{SILA_NS}}}DataTypeIdentifier"):
        (definition,) = root.xpath(
            f"sila:DataTypeDefinition[sila:Identifier='{reference.text}']", namespaces=NS
        )
        found += _string_constraints(definition.find("sila:DataType", NS), root) or []
    return found


@pytest.mark.parametrize("fdl_name", OWN_FEATURES)
def test_every_string_parameter_of_our_features_has_a_maximal_length(fdl_name: str) -> None:
    root = etree.parse(str(FEATURES_DIR / fdl_name)).getroot()
    for parameter in root.findall("sila:Command/sila:Parameter", NS):
        name = parameter.findtext("sila:Identifier", namespaces=NS)
        for constraints in _string_constraints(parameter.find("sila:DataType", NS), root):
            assert "MaximalLength" in constraints, f"{fdl_name}: parameter {name} has an unbounded string"
            assert int(constraints["MaximalLength"]) <= 255


def test_mobile_robot_controller_offers_what_the_bridge_needs() -> None:
    feature = Feature(str(FEATURES_DIR / "MobileRobotController.sila.xml"))
    assert (
        str(feature.fully_qualified_identifier)
        == "org.labwaretransfer/robotics.mobile/MobileRobotController/v1"
    )
    assert set(feature._observable_commands) == {"Dock", "Undock", "DriveToPointOfInterest"}
    assert set(feature._unobservable_commands) == {"StopMotion"}
    assert set(feature._unobservable_properties) == {"PointsOfInterest"}
    assert set(feature._observable_properties) == {
        "RobotPose",
        "RobotState",
        "CurrentPointOfInterest",
        "OnboardLabware",
    }
    assert {"UnknownPointOfInterest", "NavigationFailed", "DockingFailed", "RobotBusy"} <= set(
        feature.defined_execution_errors
    )
    root = etree.parse(str(FEATURES_DIR / "MobileRobotController.sila.xml")).getroot()
    states = root.xpath(
        "sila:Property[sila:Identifier='RobotState']//sila:Set/sila:Value/text()", namespaces=NS
    )
    assert states == ["Docked", "Idle", "Navigating", "Manipulating", "Error"]
    units = root.xpath(
        "sila:DataTypeDefinition[sila:Identifier='PlanarPose']//sila:Element/sila:Identifier/text()"
        " | sila:DataTypeDefinition[sila:Identifier='PlanarPose']//sila:Unit/sila:Label/text()",
        namespaces=NS,
    )
    assert units == ["X", "m", "Y", "m", "Theta", "rad"]
    onboard_fields = root.xpath(
        "sila:DataTypeDefinition[sila:Identifier='OnboardLabwareItem']//sila:Element/sila:Identifier/text()",
        namespaces=NS,
    )
    assert onboard_fields == ["InternalPosition", "LabwareUniqueID", "LabwareType"]


@pytest.mark.parametrize(
    ("point_of_interest", "rejected_by"),
    [("x" * 256, "MaximalLength(255)"), ("", "MinimalLength(1)"), ("x" * 255, None)],
    ids=["256 chars", "empty", "255 chars"],
)
def test_sila2_rejects_out_of_bounds_strings_as_validation_errors(
    point_of_interest: str, rejected_by: str | None
) -> None:
    """sila2 checks constraints on both ends, before any implementation code runs: a sila2 client when
    it encodes the request, and the server when it decodes one (for clients that do not check)."""
    feature = Feature(str(FEATURES_DIR / "MobileRobotController.sila.xml"))
    parameters = feature._observable_commands["DriveToPointOfInterest"].parameters
    # What any client may send: the raw message, built without the sila2 client's own check.
    request = parameters.to_message("placeholder")
    request.PointOfInterest.PointOfInterestName.value = point_of_interest
    if rejected_by is None:
        assert parameters.to_message(point_of_interest) == request
        assert parameters.to_native_type(request).PointOfInterest == point_of_interest
        return
    with pytest.raises(ValidationError, match=re.escape(f"Constraint violated: {rejected_by}")):
        parameters.to_message(point_of_interest)
    with pytest.raises(ValidationError, match=re.escape(f"Constraint violated: {rejected_by}")) as raised:
        parameters.to_native_type(request)
    assert str(raised.value.parameter_fully_qualified_identifier).endswith(
        "MobileRobotController/v1/Command/DriveToPointOfInterest/Parameter/PointOfInterest"
    )


# ---------------------------------------------------------------------------------------------------------
# SiLA core features we define ourselves: SimulationController and CancelController
# ---------------------------------------------------------------------------------------------------------


def test_simulation_controller_equals_the_standard_but_for_descriptions(tmp_path: Path) -> None:
    assert skeleton_diff(fdl_skeleton(STANDARD_SIMULATION_FDL), fdl_skeleton(OUR_SIMULATION_FDL)) == []
    standard = proto_from_fdl(STANDARD_SIMULATION_FDL, tmp_path / "standard")
    ours = proto_from_fdl(OUR_SIMULATION_FDL, tmp_path / "ours")
    assert descriptor_differences(standard, ours) == []
    assert descriptions(STANDARD_SIMULATION_FDL).isdisjoint(descriptions(OUR_SIMULATION_FDL))
    feature = Feature(str(OUR_SIMULATION_FDL))
    assert str(feature.fully_qualified_identifier) == "org.silastandard/core/SimulationController/v1"


UUID_PATTERN = r"[0-9a-f]{8}\-[0-9a-f]{4}\-[0-9a-f]{4}\-[0-9a-f]{4}\-[0-9a-f]{12}"
STANDARD_CANCEL_CONTROLLER = [
    # The standard's CancelController v1.0 (sila_base, feature_definitions/org/silastandard/core/
    # commands/CancelController.sila.xml) as skeleton lines: everything but descriptions and display
    # names, in the order of the schema (commands before errors).
    "/Feature[CancelController] [Category=core.commands FeatureVersion=1.0 MaturityLevel=Verified "
    "Originator=org.silastandard SiLA2Version=1.0] ''",
    "/Feature[CancelController]/Identifier [] 'CancelController'",
    "/Feature[CancelController]/Command[CancelCommand] [] ''",
    "/Feature[CancelController]/Command[CancelCommand]/Identifier [] 'CancelCommand'",
    "/Feature[CancelController]/Command[CancelCommand]/Observable [] 'No'",
    "/Feature[CancelController]/Command[CancelCommand]/Parameter[CommandExecutionUUID] [] ''",
    "/Feature[CancelController]/Command[CancelCommand]/Parameter[CommandExecutionUUID]/Identifier [] "
    "'CommandExecutionUUID'",
    *(
        f"/Feature[CancelController]/Command[CancelCommand]/Parameter[CommandExecutionUUID]/DataType{line}"
        for line in (
            " [] ''",
            "/Constrained [] ''",
            "/Constrained/DataType [] ''",
            "/Constrained/DataType/Basic [] 'String'",
            "/Constrained/Constraints [] ''",
            "/Constrained/Constraints/Length [] '36'",
            f"/Constrained/Constraints/Pattern [] {UUID_PATTERN!r}",
        )
    ),
    "/Feature[CancelController]/Command[CancelCommand]/DefinedExecutionErrors [] ''",
    "/Feature[CancelController]/Command[CancelCommand]/DefinedExecutionErrors/Identifier [] "
    "'InvalidCommandExecutionUUID'",
    "/Feature[CancelController]/Command[CancelCommand]/DefinedExecutionErrors/Identifier [] "
    "'OperationNotSupported'",
    "/Feature[CancelController]/Command[CancelAll] [] ''",
    "/Feature[CancelController]/Command[CancelAll]/Identifier [] 'CancelAll'",
    "/Feature[CancelController]/Command[CancelAll]/Observable [] 'No'",
    "/Feature[CancelController]/DefinedExecutionError[InvalidCommandExecutionUUID] [] ''",
    "/Feature[CancelController]/DefinedExecutionError[InvalidCommandExecutionUUID]/Identifier [] "
    "'InvalidCommandExecutionUUID'",
    "/Feature[CancelController]/DefinedExecutionError[OperationNotSupported] [] ''",
    "/Feature[CancelController]/DefinedExecutionError[OperationNotSupported]/Identifier [] "
    "'OperationNotSupported'",
]


def test_cancel_controller_has_the_standard_identifiers_types_constraints_and_errors() -> None:
    ours = [line for line in fdl_skeleton(OUR_CANCEL_FDL) if "/DisplayName [" not in line]
    assert skeleton_diff(STANDARD_CANCEL_CONTROLLER, ours) == []
    feature = Feature(str(OUR_CANCEL_FDL))
    assert str(feature.fully_qualified_identifier) == "org.silastandard/core.commands/CancelController/v1"


@pytest.mark.parametrize(
    ("execution_uuid", "accepted"),
    [
        ("0b3ed2c6-7a1e-4a51-9b43-2f3c1d7e8a90", True),
        ("0B3ED2C6-7A1E-4A51-9B43-2F3C1D7E8A90", False),  # the standard's pattern: lower case only
        ("0b3ed2c6-7a1e-4a51-9b43-2f3c1d7e8a9", False),  # 35 characters
        ("0b3ed2c6x7a1ex4a51x9b43x2f3c1d7e8a90", False),  # 36 characters, no hyphens
    ],
    ids=["lower case", "upper case", "too short", "no hyphens"],
)
def test_cancel_command_accepts_only_lower_case_uuid_strings(execution_uuid: str, accepted: bool) -> None:
    """sila2 enforces the standard's constraints before our implementation sees the UUID."""
    parameters = Feature(str(OUR_CANCEL_FDL))._unobservable_commands["CancelCommand"].parameters
    request = parameters.to_message("0b3ed2c6-7a1e-4a51-9b43-2f3c1d7e8a90")
    request.CommandExecutionUUID.value = execution_uuid
    if accepted:
        assert parameters.to_native_type(request).CommandExecutionUUID == execution_uuid
        return
    with pytest.raises(ValidationError, match="Constraint violated"):
        parameters.to_native_type(request)
