"""The SiLA servers: generated packages, their feature implementations, and how they start.

`robot_server` and `station_server` come from `sila2-codegen` (their `generated/` trees are never
edited; `codegen` regenerates them); `sila_glue` translates between sila2 and `device`; `tls`
makes the per-deployment certificates; `serving` starts a server on a checked port;
`standalone` runs one server against an already running robot side; `locking` serves the SiLA core
LockController on every server (the robot's CancelController lives in `robot_server`).
"""
