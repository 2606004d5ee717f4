"""A service request that is lost stays lost: ros2nb asks again (runtime/services.py).

Real rclpy over real DDS: a client sends a request while no server of that name exists
(as when a node of the same name just ended and the new one is not discovered yet).  That
request is never delivered; the one sent again once the server is there is answered.
"""

import threading

import pytest
import rclpy
from rcl_interfaces.srv import ListParameters
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from ros2nb import domains
from ros2nb.runtime.services import call_until_answered
from waiting import PATIENCE_S, wait_until

pytestmark = pytest.mark.ros


def test_a_lost_request_is_asked_again_and_answered():
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domains.domain_id(),
               signal_handler_options=SignalHandlerOptions.NO)
    executor = SingleThreadedExecutor(context=context)
    asker = Node('asker', context=context)
    server_node = Node('answerer', context=context, start_parameter_services=False)
    executor.add_node(asker)
    executor.add_node(server_node)
    stop = threading.Event()
    spinner = threading.Thread(target=lambda: [executor.spin_once(timeout_sec=0.05)
                                               for _ in iter(stop.is_set, True)], daemon=True)
    spinner.start()
    try:
        client = asker.create_client(ListParameters, '/answerer/list_things')
        sent = []

        def send():
            sent.append(client.call_async(ListParameters.Request()))
            if len(sent) == 1:  # sent while no server existed: the server comes only now
                server_node.create_service(ListParameters, '/answerer/list_things',
                                           lambda request, response: response)
            return sent[-1]

        done = call_until_answered(send, lambda f, s: wait_until(f.done, s), PATIENCE_S)
        assert done is not None and len(sent) >= 2 and done is not sent[0]
        assert not sent[0].done(), 'the request sent before the server existed was answered'
    finally:
        stop.set()
        spinner.join()
        executor.shutdown()
        asker.destroy_node()
        server_node.destroy_node()
        rclpy.try_shutdown(context=context)
