"""Running untrusted student programs: the process, its launcher, cgroups, isolation, ROS
domains."""
