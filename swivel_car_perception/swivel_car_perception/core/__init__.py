"""The step detector's ROS-free core: one image, and the fusion of several."""
