"""Hostile: looks for the other students' submissions and reports (a batch grades a whole
class from one folder) and prints what it can read; then works."""
import os
import time

mine = os.path.realpath(__file__)
found = 0
give_up = time.monotonic() + 3  # a look, not a search: the node must still start in time
for base in ("/tmp", "/autograder", "/data", "/srv", "/work", "/home"):
    for root, dirs, files in os.walk(base):
        if root.count(os.sep) - base.count(os.sep) > 4 or time.monotonic() > give_up:
            dirs[:] = []
            continue
        for name in files:
            path = os.path.join(root, name)
            if name in ("shouter.py", "results.json") and os.path.realpath(path) != mine:
                try:
                    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)  # a FIFO must not hang it
                    os.read(fd, 1)
                    os.close(fd)
                    print("CLASSMATE", path, flush=True)
                    found += 1
                except OSError:
                    pass
print("CLASSMATES READ:", found, flush=True)

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
