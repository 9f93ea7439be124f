"""What `sila-labware` runs: the robot side, the bridge and every SiLA server, supervised.

`stack` starts and stops one deployment, `processes` its child processes, `supervisor` restarts a
robot side that died, `demo` the standard transfer as a SiLA client. The command line that
offers all of it (and the benchmarks) is `sila_labware.cli`, above this package.
"""
