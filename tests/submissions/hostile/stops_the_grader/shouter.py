"""Hostile: finds the grading's pytest processes, tries to read their memory (where the
report's key is) and stops them with SIGSTOP, as a program of the grader's own user can
try in basic isolation; then works. The grader must not take a report from a process
something stopped."""
import os
import signal

# What it did also goes to a file: a grading it stopped keeps no output of it.
said = open(f"/tmp/stops-the-grader-{os.getuid()}.txt", "a")


def say(*words):
    print(*words, flush=True)
    print(*words, file=said, flush=True)


for name in os.listdir("/proc"):
    if not name.isdigit() or int(name) == os.getpid():
        continue
    try:
        with open(f"/proc/{name}/cmdline", "rb") as fh:
            line = fh.read()
    except OSError:
        continue
    if b"--autograder-settings" not in line:
        continue
    try:  # the kernel checks the right to trace at the open, not at each read
        with open(f"/proc/{name}/mem", "rb"):
            say("MEM OPENED", name)
    except OSError as exc:
        say("MEM DENIED", name, exc.errno)
    try:
        say("STOPPING", name)  # before: once stopped, the grading may end this program
        os.kill(int(name), signal.SIGSTOP)
    except OSError as exc:
        say("STOP DENIED", name, exc.errno)

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
