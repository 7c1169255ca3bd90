"""Hostile: leaves the machine without a free ROS domain for anyone else. A daemon of its
own locks every shared domain lock file and binds a socket on every grading domain's
first Fast DDS port, then the node works. Where it has a user of its own, other gradings
pass over what a student's user holds; it says HOARDING once it holds them (a file in
/tmp, for the test that starts a classmate's grading then)."""
import fcntl
import os
import socket
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String

FIRST, LAST, PORT_BASE, DOMAIN_GAIN = 10, 101, 7400, 250
FOLDER = "/tmp/autograder-domains"  # the machine's, whatever TMPDIR says


class Shouter(Node):
    def __init__(self):
        super().__init__('shouter')
        self.pub = self.create_publisher(String, 'shout', 10)
        self.create_subscription(String, 'words', self.on_words, 10)

    def on_words(self, msg):
        self.pub.publish(String(data=msg.data.upper()))


def hoard():
    locks, ports = 0, 0
    for domain in range(FIRST, LAST + 1):
        try:
            fd = os.open(f"{FOLDER}/domain-{domain}.lock", os.O_RDONLY | os.O_CREAT, 0o666)
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            locks += 1
        except OSError:
            pass
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            sock.bind(("127.0.0.1", PORT_BASE + DOMAIN_GAIN * domain))
            ports += 1
        except OSError:
            sock.close()
        else:
            sock.detach()  # kept open, in this process and the daemon
    return locks, ports


def main(args=None):
    locks, ports = hoard()
    print(f"HOARDING {locks} LOCKS {ports} PORTS AS UID {os.getuid()}", flush=True)
    if os.fork() == 0:  # a daemon holds them too, past the node
        os.setsid()
        while True:
            os.pause()
    with open(f"/tmp/hoarding-{os.getuid()}", "w") as fh:
        fh.write(f"{locks} {ports}\n")
    rclpy.init(args=args)
    node = Shouter()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    sys.exit(0)


if __name__ == '__main__':
    main()
