"""The robot and its stations as SiLA 2 labware-transfer devices.

Protocol logic (`sequences`, `validation`, `inventory`), device behaviour (`robot_controller`,
`station_controller`) on top of the ROS bridge, the generated server packages (`robot_server`,
`station_server`) whose feature implementations translate, and the `sila-labware` command
(`cli`, `deployment`, `processes`, `tls`, `demo`).
"""
