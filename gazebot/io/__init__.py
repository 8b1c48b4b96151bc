"""gazebot's I/O: the drivers that put the engine on a bus (ROS 2 over Zenoh, as rmw_zenoh does),
the ROS 2 message codec and recordings (CSV, C3D, MCAP, rosbag, pose folders).

I/O imports the core and nothing of :mod:`gazebot.apps`.
"""
