# The package's pure-Python modules (src/soft_body_sim/) for catkin_python_setup(): catkin links them into
# the devel space beside the generated messages and the compiled module `sim` (CMakeLists.txt).
from setuptools import setup

from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["soft_body_sim"], package_dir={"": "src"}))
