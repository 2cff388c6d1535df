"""ROS-free core of the controller: PID, limiters, steering map, command arbitration."""
