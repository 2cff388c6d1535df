"""The swivel car model: the thesis mathematics as a ROS-free library."""
