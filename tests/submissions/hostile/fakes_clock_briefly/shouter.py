"""Hostile: on the message it hears, publishes its own /clock for 0.3 s of wall time, then
destroys that publisher and answers correctly (late enough that the test is still
running the whole time its publisher is on the graph)."""

import time

import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rosgraph_msgs.msg import Clock as ClockMsg
from std_msgs.msg import String

FAKE_FOR = 0.3  # wall seconds


class Shouter(Node):
    def __init__(self):
        super().__init__('shouter')
        self.pub = self.create_publisher(String, 'shout', 10)
        self.create_subscription(String, 'words', self.on_words, 10)
        self.faked = False

    def on_words(self, msg):
        if self.faked:  # once is enough
            self.pub.publish(String(data=msg.data.upper()))
            return
        self.faked = True
        began = time.monotonic()
        publisher = self.create_publisher(ClockMsg, '/clock', 10)

        def tick():
            if time.monotonic() - began < FAKE_FOR:
                publisher.publish(ClockMsg())
                return
            self.destroy_timer(self.fake)
            self.destroy_publisher(publisher)
            print(f'FAKE CLOCK: published for {time.monotonic() - began:.2f} s', flush=True)
            self.pub.publish(String(data=msg.data.upper()))

        # A wall-clock timer: the node's own clock follows /clock, ours included.
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.fake = self.create_timer(0.02, tick, clock=steady)


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
