"""Hostile: leaves SysV shared memory, a message queue and a semaphore set, a POSIX
message queue and files in /dev/shm and /tmp behind (SysV segments of 8 MiB, touched so they
are resident), printing each key and name; then works."""
import ctypes
import ctypes.util
import os

libc = ctypes.CDLL(None, use_errno=True)
libc.shmat.restype = ctypes.c_void_p
IPC_CREAT, MB = 0o1000, 1 << 20
for index in range(3):
    key = 0x5A170000 + os.getpid() % 0x10000 * 4 + index
    shm = libc.shmget(key, 8 * MB, IPC_CREAT | 0o666)
    if shm >= 0:
        address = libc.shmat(shm, None, 0)
        if address not in (None, ctypes.c_void_p(-1).value):
            ctypes.memset(address, 1, 8 * MB)  # resident, not only reserved
    print("IPC SHM", hex(key), shm, flush=True)
print("IPC MSG", libc.msgget(0x5A180000 + os.getpid() % 0x10000, IPC_CREAT | 0o666),
      flush=True)
print("IPC SEM", libc.semget(0x5A190000 + os.getpid() % 0x10000, 4, IPC_CREAT | 0o666),
      flush=True)
rt = ctypes.CDLL(ctypes.util.find_library("rt") or "librt.so.1", use_errno=True)
queue = f"/autograder-leftover-{os.getpid()}".encode()
print("IPC MQ", queue.decode(), rt.mq_open(queue, os.O_CREAT | os.O_RDWR, 0o666, None),
      flush=True)
for folder in ("/dev/shm", "/tmp"):
    path = os.path.join(folder, f"autograder-leftover-{os.getpid()}")
    try:
        with open(path, "wb") as fh:
            fh.write(b"x" * 65536)
        print("FILE LEFT", path, flush=True)
    except OSError as exc:
        print("FILE DENIED", path, exc, flush=True)

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
