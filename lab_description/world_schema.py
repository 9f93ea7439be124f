"""The world file's one definition: pydantic models from which come the loader, its messages and
the JSON Schema editors use.

Why one definition: the README's hand-written schema, the reader and the editor's idea of the file
drifted apart, and a misspelt key was silently ignored. Here every key is declared once, with its
unit, frame and range; unknown keys are refused at any depth. Rules that span fields (unique names,
plates on existing nests) are in `world_rules`. Angles are degrees, as in the file; `world.py` turns
the validated file into the frozen dataclasses the program reads (radians there).

    python -m lab_description.world_schema            # print the JSON Schema
    python -m lab_description.world_schema --write    # rewrite the shipped worlds/world.schema.json
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, Strict

SCHEMA_FILE = Path(__file__).resolve().parent / "worlds" / "world.schema.json"
SCHEMA_ID = "world.schema.json"
MIRROR_AMBIGUOUS_MARKER_IDS = frozenset({8, 9, 17, 47})
MARKER_DICTIONARY_SIZE = 50  # DICT_4X4_50

# Strict scalars: YAML's `true` is no number and "2" no integer (pydantic would convert them).
Number = Annotated[float, Strict(), Field(allow_inf_nan=False)]
Integer = Annotated[int, Strict()]
Text = Annotated[str, Strict(), Field(min_length=1)]
Vector3 = tuple[Number, Number, Number]
Positive = Annotated[Number, Field(gt=0.0)]


def _not_mirror_ambiguous(marker_id: int) -> int:
    if marker_id in MIRROR_AMBIGUOUS_MARKER_IDS:
        avoid = ", ".join(str(i) for i in sorted(MIRROR_AMBIGUOUS_MARKER_IDS))
        raise ValueError(f"id {marker_id} also decodes when mirrored; avoid {avoid}")
    return marker_id


MarkerId = Annotated[
    Integer,
    Field(ge=0, le=MARKER_DICTIONARY_SIZE - 1, json_schema_extra={"not": {"enum": [8, 9, 17, 47]}}),
    AfterValidator(_not_mirror_ambiguous),
]


class _Strict(BaseModel):
    """Every part of the file refuses keys it does not declare."""

    model_config = ConfigDict(extra="forbid", frozen=True)


PoseList = Annotated[
    Vector3,
    Field(
        description="[x, y, yaw] in the world frame: x, y in metres on the floor, yaw in degrees "
        "counter-clockwise from the world x axis"
    ),
]


class Dock(_Strict):
    """The charging dock: where the robot starts and the POI in front of it."""

    pose: PoseList = Field(
        description="[x, y, yaw_deg] of base_footprint when docked, world frame (m, m, degrees); "
        "the dock stands behind the robot"
    )
    poi: Text = Field(description="name of the POI `approach_distance` in front of the docked pose")
    approach_distance: Number = Field(
        0.6, ge=0.3, le=2.0, description="distance (m) from the docked pose to its POI, along the heading"
    )


class Robot(_Strict):
    """The robot's start and its onboard plate holder."""

    start: Literal["docked"] = Field("docked", description="where the robot starts; only 'docked'")
    hotel_slots: Integer = Field(
        2, ge=1, le=2, description="pockets of the onboard hotel in use (the holder has two)"
    )


class Sensors(_Strict):
    """Plate sensors the lab has added. A stock TIAGo++ has none: without them the robot checks a
    nest with its head camera and its hotel with the fingers' gap, and goals name the plates."""

    nests: bool = Field(True, description="a presence sensor in every nest (published on /station_states)")
    hotel: bool = Field(True, description="a presence sensor in every onboard hotel pocket")
    label_readers: bool = Field(
        True, description="barcode readers at every nest and pocket and in the gripper's palm"
    )


class LabwareType(_Strict):
    """A plate type: its outer box and mass (the plate's frame: x along the long side, z up)."""

    length: Number = Field(ge=0.01, le=0.5, description="long side (m)")
    width: Number = Field(ge=0.01, le=0.5, description="short side (m): the fingers close across it")
    height: Number = Field(ge=0.002, le=0.2, description="height (m)")
    mass: Number = Field(ge=0.01, le=3.0, description="mass (kg)")


class Table(_Strict):
    """The bench: a box whose table frame is the centre of its top."""

    pose: PoseList = Field(
        description="[x, y, yaw_deg] of the table frame on the floor plan, world frame (m, m, degrees); "
        "table x points away from the side the robot works from"
    )
    size: tuple[Positive, Positive, Positive] = Field(
        description="[depth, width, top_height] (m): depth along table x, width along table y, "
        "top surface above the floor"
    )


class Marker(_Strict):
    """The station's ArUco marker (DICT_4X4_50); the robot finds the nests from it."""

    id: MarkerId = Field(
        description="ArUco id, 0..49, unique in the lab, not 8, 9, 17 or 47 (mirror-ambiguous)"
    )
    size: Number = Field(ge=0.10, le=0.5, description="side of the black square (m)")
    xyz: Vector3 = Field(description="marker centre in the table frame (m)")
    rpy: Vector3 = Field(
        (0.0, 0.0, 0.0),
        description="marker frame orientation in the table frame, roll, pitch, yaw (degrees); "
        "[90, 0, -90] = upright, facing the robot (marker frame as OpenCV: x right, y up, z out of the face)",
    )


class Nests(_Strict):
    """A row of nests (sub-positions 1..n), given relative to the marker, as the robot finds them."""

    site_in_marker_xyz: Vector3 = Field(
        description="sub-position 1's site (nest floor centre, where the plate's bottom centre rests) "
        "in the marker frame (m)"
    )
    site_in_marker_rpy: Vector3 = Field(
        (0.0, 0.0, 0.0),
        description="site orientation in the marker frame, roll, pitch, yaw (degrees); "
        "[-90, 0, 0] = level, plate long side along marker x",
    )
    sub_positions: Integer = Field(ge=1, le=20, description="number of nests in the row")
    spacing: Number = Field(
        0.0, ge=0.0, le=2.0, description="between neighbouring nests along the site x axis (m)"
    )
    clearance: Number = Field(ge=0.0005, le=0.02, description="per side between plate and nest brackets (m)")
    approach_height: Annotated[Number, Field(ge=0.02, le=0.4)] | None = Field(
        None,
        description="override: the approach pose is this far above the site, along site z (m); "
        "default: chosen by the robot (0.10 m, lower where the arm cannot reach that high)",
    )


class StationPoi(_Strict):
    """Where the robot stands to work at the station (heading: the table's, facing table +x). Only the
    name is the lab's; the distances are overrides of what the robot derives from the bench, the nests
    and its own model (lab_description.station_placement)."""

    name: Text | None = Field(
        None, description="unique POI name where the robot works (default: <station>_work)"
    )
    standoff: Annotated[Number, Field(ge=0.3, le=1.2)] | None = Field(
        None,
        description="override: navigation stops base_footprint this far (m) in front of the middle of "
        "the nest row (the POI); default: work_standoff + 0.22",
    )
    work_standoff: Annotated[Number, Field(ge=0.3, le=1.0)] | None = Field(
        None,
        description="override: the marker-guided final approach brings base_footprint this close (m) to "
        "work; default: the nearest that keeps the bench's front edge 0.37 m ahead (the standoff, if "
        "only that is given)",
    )
    lateral: Annotated[Number, Field(ge=-0.5, le=0.5)] | None = Field(
        None,
        description="override: and this far (m) to its left; default: the row's middle in the middle of "
        "the right arm's 0.45 m band (0.225)",
    )


class Station(_Strict):
    """A bench with an ArUco marker and a row of nests: a SiLA handover position."""

    name: Text = Field(description="unique station name: the SiLA handover position name")
    table: Table
    marker: Marker
    nests: Nests
    poi: StationPoi = Field(default_factory=StationPoi, description="where the robot works (all optional)")


class PlateStart(_Strict):
    """A plate at the start: either in a station's nest or in an onboard hotel slot."""

    model_config = ConfigDict(
        json_schema_extra={
            "oneOf": [
                {
                    "required": ["hotel_slot"],
                    "not": {"anyOf": [{"required": ["station"]}, {"required": ["sub_position"]}]},
                },
                {"required": ["station", "sub_position"], "not": {"required": ["hotel_slot"]}},
            ]
        }
    )

    id: Text = Field(description="unique labware id")
    type: Text = Field(description="its labware type: a key of labware_types")
    station: Text | None = Field(None, description="the station whose nest holds it (with sub_position)")
    sub_position: Annotated[Integer, Field(ge=1, le=20)] | None = Field(
        None, description="the nest, 1..the station's sub_positions"
    )
    hotel_slot: Annotated[Integer, Field(ge=1, le=2)] | None = Field(
        None, description="or the onboard hotel slot, 1..robot.hotel_slots"
    )


class Obstacle(_Strict):
    """A free-standing obstacle on the floor (a cart, a pillar, a wall, a fridge): a box or an
    upright cylinder standing on the floor. It is built in the physics, drawn, and on the map."""

    model_config = ConfigDict(
        json_schema_extra={
            "oneOf": [
                {
                    "properties": {"shape": {"const": "box"}},
                    "required": ["size"],
                    "not": {"required": ["radius"]},
                },
                {
                    "properties": {"shape": {"const": "cylinder"}},
                    "required": ["radius"],
                    "not": {"required": ["size"]},
                },
            ]
        }
    )

    name: Text = Field(description="unique obstacle name (collision reports name it)")
    shape: Literal["box", "cylinder"] = Field(description="'box' (give size) or 'cylinder' (give radius)")
    pose: PoseList = Field(
        description="[x, y, yaw_deg] of the obstacle's centre on the floor, world frame (m, m, degrees)"
    )
    size: tuple[Positive, Positive] | None = Field(
        None, description="box only: [length, width] (m), length along the pose's heading"
    )
    radius: Annotated[Number, Field(gt=0.0, le=5.0)] | None = Field(
        None, description="cylinder only: radius (m)"
    )
    height: Number = Field(1.0, gt=0.0, le=3.0, description="height above the floor (m)")


class WorldFile(_Strict):
    """A lab for the simulated TIAGo++: dock, POIs, stations with markers and nests, labware, plates.
    Units: metres, kilograms; angles in degrees."""

    model_config = ConfigDict(title="sila-labware world file")

    name: Text | None = Field(
        None, description="the lab's name; the SiLA servers carry it (default: the file name)"
    )
    floor_size: Number = Field(
        12.0, ge=2.0, le=100.0, description="side of the square floor (m), centred on the world origin"
    )
    dock: Dock
    pois: dict[str, PoseList] = Field(
        default_factory=dict,
        description="extra named floor poses: name -> [x, y, yaw_deg], world frame (m, m, degrees)",
    )
    robot: Robot
    sensors: Sensors = Field(
        default_factory=Sensors, description="lab-added plate sensors (default: all present)"
    )
    labware_types: dict[str, LabwareType] = Field(description="plate types by name")
    stations: list[Station] = Field(min_length=1, description="one entry per station, any number")
    plates: list[PlateStart] = Field(
        default_factory=list, description="the plates at the start, each in a nest or a hotel slot"
    )
    obstacles: list[Obstacle] = Field(
        default_factory=list,
        description="free-standing boxes and cylinders on the floor (besides the benches and the "
        "floor's edge walls); inside the floor, clear of every bench, POI and the dock",
    )


def json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of the world file, as shipped in world.schema.json."""
    schema = WorldFile.model_json_schema()
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": SCHEMA_ID, **schema}


def schema_text() -> str:
    return json.dumps(json_schema(), indent=2, sort_keys=True) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m lab_description.world_schema", description=__doc__.split("\n")[0]
    )
    parser.add_argument("--write", action="store_true", help=f"rewrite {SCHEMA_FILE}")
    args = parser.parse_args(argv)
    if args.write:
        SCHEMA_FILE.write_text(schema_text())
        sys.stdout.write(f"wrote {SCHEMA_FILE}\n")
    else:
        sys.stdout.write(schema_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
