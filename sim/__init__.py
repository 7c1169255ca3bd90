"""A pymunk 2D world exposed as ROS 2 nodes: a small differential-drive robot in an arena."""
