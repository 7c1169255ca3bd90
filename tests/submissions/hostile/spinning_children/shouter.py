"""Hostile: six children that spin on the CPU for as long as the node lives, to slow down
the gradings running beside it; the node itself works. Its processes share one CPU share
(a cpu cgroup of its own), so it slows only itself."""
import os
import time

for _child in range(6):
    if os.fork() == 0:
        end = time.monotonic() + 600
        while time.monotonic() < end:
            pass
        os._exit(0)

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class Shouter(Node):
    def __init__(self):
        super().__init__('shouter')
        self.pub = self.create_publisher(String, 'shout', 10)
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
