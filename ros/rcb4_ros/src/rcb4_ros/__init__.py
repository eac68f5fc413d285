"""rcb4_ros: a ROS 1 node for KONDO's RCB-4 over pyrcb4 (see node.py)."""
