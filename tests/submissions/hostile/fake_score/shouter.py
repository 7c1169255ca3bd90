"""Hostile: its output tries to lie. It clears the screen and shows a fake full score,
hides text, sets the window title, plants a link, reverses a line with a bidi override,
writes NUL, BEL and C1 bytes (which also make JUnit XML not well-formed); then works."""
import sys

ESC, BEL = "\x1b", "\x07"
LIE = (f"{ESC}[2J{ESC}[H{ESC}[1;32m"  # clear the screen, home, bold green
       " ✔     1/1  The node starts and publishes on shout\n"
       " ✔     1/1  What it hears comes out upper-cased\n"
       " ✔     1/1  Each message is answered exactly once\n\n"
       f"Score: 13/13 (100%), passed (pass mark 70%){ESC}[0m\n"
       f"{ESC}[8mthe real verdict is below, hidden{ESC}[28m\n"  # concealed text
       f"{ESC}]0;autograder: all tests passed{BEL}"  # OSC 0: the window's title
       f"{ESC}]8;;https://example.invalid/regrade{ESC}\\Ask for a regrade{ESC}]8;;{ESC}\\\n"
       "\u202edessap stset lla\u202c\n"  # U+202E: this line reads right to left
       f"NUL\x00 BEL{BEL} CR\r overwritten\n")
sys.stdout.write(LIE)
sys.stderr.write(LIE)
sys.stdout.buffer.write(b"C1 CSI \xc2\x9b2J and a raw \x9b byte\n")
sys.stdout.flush()

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
