"""soft_body_sim from Python: `sim`, the simulator as a library (docs/python.md), beside the ROS messages
(`soft_body_sim.msg`, `.srv`) and the dynamic_reconfigure configurations (`.cfg`) that catkin generates."""

# The devel space's soft_body_sim/__init__.py puts src/ first on sys.path, and a process spawned from one that
# imported it (a local Dask cluster's worker) inherits that sys.path and finds this folder as the package:
# the compiled `sim` and the generated msg, srv and cfg are in the devel space's folder of the same name.
# Extending the path joins the two, as the devel space's __init__ does (a no-op when installed).
import pkgutil

__path__ = pkgutil.extend_path(__path__, __name__)
del pkgutil
