"""The swivel car stack in one process, without ROS (see ``inprocess``)."""
