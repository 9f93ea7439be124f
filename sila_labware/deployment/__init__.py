"""What `sila-labware` runs: the robot side, the bridge and every SiLA server, supervised.

`stack` starts and stops one deployment, `processes` its child processes, `supervisor` restarts a
robot side that died, `cli` is the command line, `demo` the standard transfer as a SiLA client.
"""
