"""Autograder and quizzes for the rclpy chapter (ROS 2 Jazzy) on a pymunk world."""

__version__ = "0.1.0"
