"""Hostile: a correct shouter with a thread left in uninterruptible sleep (state D) for
good, to hold simulation time: through ctypes (which lets the GIL go) it asks
posix_spawn for a child that opens a FIFO no one writes, and glibc's vfork-style spawn
keeps the asking thread waiting in the kernel until that child goes on."""

import ctypes
import os
import threading

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


def stay_in_the_kernel():
    libc = ctypes.CDLL(None, use_errno=True)
    fifo = os.path.abspath('never_written')
    os.mkfifo(fifo)
    actions = ctypes.create_string_buffer(256)  # posix_spawn_file_actions_t, with room
    libc.posix_spawn_file_actions_init(actions)
    libc.posix_spawn_file_actions_addopen(actions, 3, fifo.encode(), os.O_RDONLY, 0)
    pid = ctypes.c_int()
    argv = (ctypes.c_char_p * 2)(b'true', None)
    envp = (ctypes.c_char_p * 1)(None)
    print('BLOCKING', flush=True)
    libc.posix_spawn(ctypes.byref(pid), b'/bin/true', actions, None, argv, envp)


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
    threading.Thread(target=stay_in_the_kernel, daemon=True).start()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
