"""Step-climbing planner for the swivel car: a ROS-free core and the planner node."""
