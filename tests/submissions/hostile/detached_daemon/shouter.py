"""Hostile: starts a daemon in a new session that would outlive the node.

Both say which user they run as: the grader checks it is the run's own (strict isolation)."""

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


def _daemon():
    import os
    import time
    if os.fork() == 0:
        os.setsid()
        if os.fork() == 0:
            print("STUDENT UID", os.getuid(), flush=True)
            while True:
                time.sleep(1)
        os._exit(0)
    os.wait()


def main(args=None):
    import os
    print("STUDENT UID", os.getuid(), flush=True)
    _daemon()
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
