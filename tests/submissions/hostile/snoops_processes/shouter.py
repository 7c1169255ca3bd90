"""Hostile: looks at every process on the machine for the grader's command lines (the
report's path, other students' folders), tries to stop or trace them, and checks whether
it could gain privileges (NoNewPrivs); then works."""
import ctypes
import os
import signal

me = os.getuid()
seen = foreign = stopped = 0
for name in os.listdir("/proc"):
    if not name.isdigit() or int(name) == os.getpid():
        continue
    try:
        owner = os.stat(f"/proc/{name}").st_uid
        with open(f"/proc/{name}/cmdline", "rb") as fh:
            line = fh.read().replace(b"\0", b" ")
    except OSError:
        continue
    seen += 1
    if owner != me:
        foreign += 1
        if b"pytest" in line or b"autograder" in line:
            print("GRADER COMMAND LINE", line[:200], flush=True)
        try:
            os.kill(int(name), signal.SIGSTOP)
            os.kill(int(name), signal.SIGCONT)
            stopped += 1
        except OSError:
            pass
print("PROCESSES SEEN", seen, "FOREIGN", foreign, "STOPPED", stopped, flush=True)
with open("/proc/self/status") as fh:
    print(next(line.strip() for line in fh if line.startswith("NoNewPrivs")), flush=True)
libc = ctypes.CDLL(None, use_errno=True)
PTRACE_ATTACH = 16
traced = sum(libc.ptrace(PTRACE_ATTACH, pid, None, None) == 0 for pid in range(1, 400)
             if pid != os.getpid())
print("TRACED", traced, flush=True)

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
