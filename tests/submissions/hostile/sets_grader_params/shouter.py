"""Hostile: before its node starts, tries to turn off use_sim_time on the grader's nodes
through their parameter services, and says what happened; then behaves correctly."""

import rclpy
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String

TARGETS = ('/sim_world', '/autograder_probe')


def meddle(node):
    """Set use_sim_time false on each target; print what happened."""
    for target in TARGETS:
        client = node.create_client(SetParameters, f'{target}/set_parameters')
        if not client.wait_for_service(timeout_sec=1.5):
            print(f'PARAMS: no service {target}/set_parameters', flush=True)
            continue
        off = ParameterValue(type=ParameterType.PARAMETER_BOOL, bool_value=False)
        future = client.call_async(SetParameters.Request(
            parameters=[Parameter(name='use_sim_time', value=off)]))
        rclpy.spin_until_future_complete(node, future, timeout_sec=2.0)
        results = future.result().results if future.done() else []
        if results and results[0].successful:
            print(f'PARAMS: changed use_sim_time on {target}', flush=True)
        else:
            print(f'PARAMS: refused on {target}', flush=True)


class Shouter(Node):
    def __init__(self):
        super().__init__('shouter')
        self.pub = self.create_publisher(String, 'shout', 10)
        self.create_subscription(String, 'words', self.on_words, 10)

    def on_words(self, msg):
        self.pub.publish(String(data=msg.data.upper()))


def main(args=None):
    rclpy.init(args=args)
    meddler = Node('meddler')  # before the graded node: the grader waits for that one
    meddle(meddler)
    meddler.destroy_node()
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
