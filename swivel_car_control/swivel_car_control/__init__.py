"""Swivel car control: swivel PID, cmd_vel handling and odometry."""
