"""ROS glue shared by every swivel car node (no node of its own)."""
