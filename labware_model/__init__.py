"""The labware model: labware types, plates, and the holders a plate can be in, named once for every layer.

The bottom layer: pure Python (standard library only), imported by `tiago_sim`, `ros_bridge` and
`sila_labware` alike and importing none of them. Modules:
- `labware`: `LabwareType` (sizes in metres, mass in kilograms) and `Plate` (an id and a type name);
- `holders`: `Nest` (a station's nest), `HotelSlot` (a pocket of the robot's hotel), the gripper,
  and the places off every holder (the floor, unknown); `Location` is any of them, with one text
  form ("station:NAME:N", "hotel:N", "gripper", "floor", "unknown") and its parser;
- `readings`: what sensors and the physics report about holders (`NestReading`,
  `HotelSlotReading`, `PlacementCheck`);
- `workcell`: what the robot side serves (`WorkcellDescription`: stations with their nests, the
  hotel's slot count, the POIs), as /describe_workcell reports it.

Geometry stays with its owner: the world file's poses of tables, markers and nests belong to
`lab_description.world`; here a nest is a name and a number. Everything is frozen and checks its
values when built (a `ValueError` says which value is wrong), so it is safe on any thread.
"""
