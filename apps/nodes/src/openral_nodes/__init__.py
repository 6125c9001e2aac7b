"""ROS 2 nodes of openral: the manifest lifecycle node and the rskill runner."""
