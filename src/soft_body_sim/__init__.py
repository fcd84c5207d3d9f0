"""soft_body_sim from Python: `sim`, the simulator as a library (docs/python.md), beside the ROS messages
(`soft_body_sim.msg`, `.srv`) and the dynamic_reconfigure configurations (`.cfg`) that catkin generates."""
