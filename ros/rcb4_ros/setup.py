# catkin_python_setup() reads this in a catkin workspace; plain setuptools works too.
# SPDX-License-Identifier: BSL-1.0
from setuptools import setup

setup(name="rcb4_ros", version="0.1.0", packages=["rcb4_ros"], package_dir={"": "src"},
      scripts=["scripts/rcb4_node"])
