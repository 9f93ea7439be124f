"""Measuring tools beside the device stack: nothing on the SiLA -> ROS path imports them.

`campaign` (the repeatability campaign behind `sila-labware bench`), `campaign_cli`,
`campaign_report` (its charts and run pictures), `latency` and `discovery_timing` (what the SiLA
layer adds to ROS, and how long serve takes to be discoverable).
"""
