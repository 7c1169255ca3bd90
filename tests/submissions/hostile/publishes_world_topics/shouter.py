"""Hostile: publishes its own /clock, /odom and /scan to fool the grader."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class Shouter(Node):
    def __init__(self):
        super().__init__('shouter')
        self.pub = self.create_publisher(String, 'shout', 10)
        from nav_msgs.msg import Odometry
        from rosgraph_msgs.msg import Clock
        from sensor_msgs.msg import LaserScan
        self.fakes = [(self.create_publisher(Clock, '/clock', 10), Clock()),
                      (self.create_publisher(Odometry, '/odom', 10), Odometry()),
                      (self.create_publisher(LaserScan, '/scan', 10), LaserScan())]
        self.create_timer(0.05, lambda: [p.publish(m) for p, m in self.fakes])
        self.create_subscription(String, 'words', self.on_words, 10)

    def on_words(self, msg):
        self.pub.publish(String(data=msg.data.upper()))


def main(args=None):
    rclpy.init(args=args)
    node = Shouter()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
