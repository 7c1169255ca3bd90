"""Hostile: tries to overwrite the grader's report and write into its folders."""
import glob
import json
import os

fake = json.dumps({"tests": [], "data": {}, "forged": True})
for path in glob.glob("/tmp/autograder-*/report.json"):
    try:
        with open(path, "w") as fh:
            fh.write(fake)
        print("FORGED", path, flush=True)
    except OSError as exc:
        print("DENIED", path, exc, flush=True)
for folder in glob.glob("/tmp/autograder-*"):
    if folder == os.getcwd():
        continue  # its own working directory is its to write
    try:
        with open(os.path.join(folder, "planted.txt"), "w") as fh:
            fh.write("planted")
        print("PLANTED", folder, flush=True)
    except OSError as exc:
        print("DENIED", folder, exc, flush=True)

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
