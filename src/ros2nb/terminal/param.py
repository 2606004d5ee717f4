"""``ros2 param list/get/set/describe/dump``: a node's parameters, through its parameter services.

Introduced in ``08-parameters.ipynb``.  Every rclpy node serves its parameters on six
services (``/NODE/list_parameters``, ``get_parameters``, ``set_parameters``, ...); these
verbs call them from the kernel's hidden node with rclpy's own ``AsyncParameterClient``,
as ros2cli does, and print what the CLI prints.  With a real ``ros2`` on PATH they run it
instead (on the kernel's domain) and show its output.  Either way the node answers
itself: its descriptors' ranges and its on-set callback decide whether a ``set`` succeeds.
"""

from __future__ import annotations

import ast
import contextlib
import os
import shutil
import subprocess
import time
from typing import Any, Callable, Iterator, Optional

import yaml
from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.msg import ParameterType
from rclpy.client import Client
from rclpy.parameter import Parameter, get_parameter_value, parameter_value_to_python
from rclpy.parameter_client import AsyncParameterClient

from ..errors import Ros2nbError, UsageError
from ..runtime import current_runtime
from ..runtime.services import call_until_answered
from .run import node_process_env

#: Seconds a verb waits for the node's parameter services and their answer (wall clock).
SERVICE_WAIT_S = 10.0
#: ``ros2 param get``'s label per parameter type.
GET_LABELS = {
    ParameterType.PARAMETER_BOOL: 'Boolean value is:',
    ParameterType.PARAMETER_INTEGER: 'Integer value is:',
    ParameterType.PARAMETER_DOUBLE: 'Double value is:',
    ParameterType.PARAMETER_STRING: 'String value is:',
    ParameterType.PARAMETER_BYTE_ARRAY: 'Byte values are:',
    ParameterType.PARAMETER_BOOL_ARRAY: 'Boolean values are:',
    ParameterType.PARAMETER_INTEGER_ARRAY: 'Integer values are:',
    ParameterType.PARAMETER_DOUBLE_ARRAY: 'Double values are:',
    ParameterType.PARAMETER_STRING_ARRAY: 'String values are:',
}
#: ``ros2 param describe``'s type names.
TYPE_NAMES = {
    ParameterType.PARAMETER_NOT_SET: 'not set', ParameterType.PARAMETER_BOOL: 'boolean',
    ParameterType.PARAMETER_INTEGER: 'integer', ParameterType.PARAMETER_DOUBLE: 'double',
    ParameterType.PARAMETER_STRING: 'string', ParameterType.PARAMETER_BYTE_ARRAY: 'byte array',
    ParameterType.PARAMETER_BOOL_ARRAY: 'boolean array',
    ParameterType.PARAMETER_INTEGER_ARRAY: 'integer array',
    ParameterType.PARAMETER_DOUBLE_ARRAY: 'double array',
    ParameterType.PARAMETER_STRING_ARRAY: 'string array',
}


def _absolute(node: str) -> str:
    if not isinstance(node, str) or not node.strip('/'):
        raise UsageError("Name the node, e.g. param_list('temperature_monitor').")
    return node if node.startswith('/') else '/' + node


def _real_ros2(*args: str) -> Optional[str]:
    """Run ``ros2 param ARGS`` when a real ``ros2`` is on PATH; its output, else None."""
    real = shutil.which('ros2')
    if real is None:
        return None
    done = subprocess.run([real, 'param', *args], env=node_process_env(os.environ), text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, check=False)
    print(done.stdout, end='')
    return done.stdout


def _idle_in_this_kernel(rt: Any, name: str) -> bool:
    """True for a node of this kernel's process that ros2nb does not spin (never added, or its
    constructor raised after ``super().__init__``): its services would never answer."""
    prefix = rt.participant_prefix()
    if prefix is None or any(node.get_fully_qualified_name() == name
                             for node in rt.nodes.values()):
        return False
    return any(info.node_namespace.rstrip('/') + '/' + info.node_name == name
               and bytes(info.endpoint_gid[:12]) == prefix
               for info in rt.node.get_publishers_info_by_topic('/rosout'))


class _Client:
    """An ``AsyncParameterClient`` on the kernel's hidden node, for one call of a verb."""

    def __init__(self, node: str) -> None:
        self.name = _absolute(node)
        self.rt = current_runtime()
        known = {(ns.rstrip('/') + '/' + n) for n, ns in
                 self.rt.node.get_node_names_and_namespaces()}
        if self.name not in known:
            raise Ros2nbError(f'Node not found: {self.name} is not in the ROS graph '
                              '(node_list() shows the running nodes).')
        if _idle_in_this_kernel(self.rt, self.name):
            raise Ros2nbError(f'{self.name} was created in this kernel but does not spin, so '
                              'nobody answers its parameter services: hand it over with '
                              'ros2nb.add(node), or fix what stopped its constructor.')
        with self.rt.exclusive():
            self.client = AsyncParameterClient(self.rt.node, self.name)
        if not self.client.wait_for_services(SERVICE_WAIT_S):
            self.close()
            raise Ros2nbError(f'{self.name} does not answer parameter calls (its services did '
                              f'not appear within {SERVICE_WAIT_S:g} s): is it spinning?')

    def answer(self, send: Callable[[], Any]) -> Any:
        """Ask with ``send()`` (again now and then: a request or reply can be lost right
        after a node appeared) until the node answers."""
        def wait(future: Any, seconds: float) -> bool:
            until = time.monotonic() + seconds
            while not future.done() and time.monotonic() < until:
                time.sleep(0.002)
            return future.done()

        done = call_until_answered(send, wait, SERVICE_WAIT_S)
        if done is None:
            raise Ros2nbError(f'{self.name} did not answer within {SERVICE_WAIT_S:g} s: is '
                              'it spinning (ros2nb.add(node))?')
        self.rt.print_pending()
        return done.result()

    def close(self) -> None:
        with self.rt.exclusive():
            for client in [c for c in vars(self.client).values() if isinstance(c, Client)]:
                self.rt.node.destroy_client(client)


@contextlib.contextmanager
def _client(node: str) -> Iterator[_Client]:
    client = _Client(node)
    try:
        yield client
    finally:
        client.close()


def _names(client: _Client) -> list[str]:
    return sorted(client.answer(client.client.list_parameters).result.names)


def param_list(node: str) -> list[str]:
    """Print a node's parameter names, like ``ros2 param list NODE``.

    Introduced in ``08-parameters.ipynb``.

    :param node: the node's name, e.g. ``'temperature_monitor'``.
    :return: the names, sorted.
    :raises Ros2nbError: ``Node not found``, or a node that does not answer.
    """
    out = _real_ros2('list', _absolute(node))
    if out is not None:
        return [line.strip() for line in out.splitlines() if line.startswith('  ')]
    with _client(node) as client:
        names = _names(client)
    for name in names:
        print(f'  {name}')
    return names


def _values(client: _Client, names: list[str]) -> list[Any]:
    return list(client.answer(lambda: client.client.get_parameters(names)).values)


def param_get(node: str, name: str) -> Any:
    """Print one parameter's type and value, like ``ros2 param get NODE NAME``.

    Introduced in ``08-parameters.ipynb``.

    :return: the value (a Python float, int, bool, str or list), None when not set.
    :raises Ros2nbError: ``Node not found``, or ``Parameter not set`` (the CLI's texts).
    """
    out = _real_ros2('get', _absolute(node), name)
    if out is not None:
        text = out.strip().split(': ', 1)[-1]
        try:
            return ast.literal_eval(text)
        except (ValueError, SyntaxError):
            return text
    with _client(node) as client:
        if name not in _names(client):
            raise Ros2nbError(f'Parameter not set: {client.name} has no parameter {name} '
                              f'(param_list({client.name!r}) shows its parameters).')
        value = _values(client, [name])[0]
    python = parameter_value_to_python(value)
    if value.type == ParameterType.PARAMETER_NOT_SET:
        print('Parameter not set.')
        return None
    print(GET_LABELS[value.type], list(python) if isinstance(python, tuple) else python)
    return python


def _as_parameter(name: str, value: Any) -> Parameter:
    """``value`` as ``ros2 param set`` reads it: a string is parsed as YAML, like the CLI."""
    if isinstance(value, str):
        return Parameter.from_parameter_msg(
            ParameterMsg(name=name, value=get_parameter_value(string_value=value)))
    try:
        return Parameter(name, value=value)
    except TypeError:
        raise UsageError(f'{value!r} is no parameter value: give a number, a bool, a string '
                         'or a list of one of them.') from None


def param_set(node: str, name: str, value: Any) -> bool:
    """Set one parameter, like ``ros2 param set NODE NAME VALUE``; print the node's answer.

    The node decides: its descriptor (type, range, read-only) and its on-set callback may
    refuse, with a reason.

    Introduced in ``08-parameters.ipynb``.

    :param value: the new value; a string is read as the CLI reads it (``'25.0'`` is a
        double, ``'true'`` a bool).
    :return: True when the node accepted the value.
    :raises Ros2nbError: ``Node not found``, or a node that does not answer.
    """
    out = _real_ros2('set', _absolute(node), name, str(value))
    if out is not None:
        return out.startswith('Set parameter successful')
    parameter = _as_parameter(name, value)
    with _client(node) as client:
        result = client.answer(lambda: client.client.set_parameters([parameter])).results[0]
    if result.successful:
        print('Set parameter successful' + (f': {result.reason}' if result.reason else ''))
    else:
        print('Setting parameter failed' + (f': {result.reason}' if result.reason else ''))
    return bool(result.successful)


def param_describe(node: str, *names: str) -> list[Any]:
    """Print parameters' descriptors, like ``ros2 param describe NODE NAME...``.

    Introduced in ``08-parameters.ipynb``.

    :return: the ``rcl_interfaces/msg/ParameterDescriptor`` messages.
    :raises Ros2nbError: ``Node not found``, or a node that does not answer.
    """
    if not names:
        raise UsageError("Name one or more parameters, e.g. param_describe('temperature_monitor', "
                         "'high_above_c').")
    if _real_ros2('describe', _absolute(node), *names) is not None:
        return []
    with _client(node) as client:
        descriptors = list(client.answer(lambda: client.client.describe_parameters(list(names)))
                           .descriptors)
    for descriptor in descriptors:
        print('Parameter name:', descriptor.name)
        print('  Type:', TYPE_NAMES.get(descriptor.type, descriptor.type))
        if descriptor.description:
            print('  Description:', descriptor.description)
        print('  Constraints:')
        if descriptor.read_only:
            print('    Read only: true')
        ranges = list(descriptor.floating_point_range) + list(descriptor.integer_range)
        if ranges:
            print('    Min value:', ranges[0].from_value)
            print('    Max value:', ranges[0].to_value)
            if ranges[0].step:
                print('    Step:', ranges[0].step)
        if descriptor.additional_constraints:
            print('    Additional constraints:', descriptor.additional_constraints)
    return descriptors


def param_dump(node: str) -> str:
    """Print every parameter of a node as a parameters file, like ``ros2 param dump NODE``.

    The text is what ``--ros-args --params-file FILE`` reads back.

    Introduced in ``08-parameters.ipynb``.

    :return: the YAML text.
    :raises Ros2nbError: ``Node not found``, or a node that does not answer.
    """
    out = _real_ros2('dump', _absolute(node))
    if out is not None:
        return out
    with _client(node) as client:
        names = _names(client)
        values = _values(client, names)
        full = client.name
    parameters: dict[str, Any] = {}
    for name, value in zip(names, values):
        python = parameter_value_to_python(value)
        parameters[name] = list(python) if isinstance(python, tuple) else python
    text = yaml.safe_dump({full: {'ros__parameters': parameters}}, default_flow_style=False)
    print(text, end='')
    return text
