"""The robot and its stations as SiLA 2 labware-transfer devices.

Layers, each a subpackage that imports only the ones listed before it:
- `device`: the devices' behaviour with no sila2 in it: protocol order (`sequences`), parameter
  checks (`validation`), the inventory, the robot and station controllers, their errors;
- `servers`: the SiLA servers generated from features/ (`robot_server`, `station_server`), the
  glue between sila2 and `device`, TLS, port checks and the standalone start-up;
- `deployment`: what `sila-labware` runs: child processes, the supervisor, the demo;
- `benchmarks`: the repeatability campaign, its report and the bridge latency benchmark;
- `cli`: the `sila-labware` command on top of all of them (`python -m sila_labware` runs it).
"""
