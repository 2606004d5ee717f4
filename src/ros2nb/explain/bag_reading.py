"""One line for the mistakes of reading a bag with rosbags: a type the bag does not hold, and
the /rosout messages read as readings.

Part of :mod:`ros2nb.explain` (:func:`~ros2nb.explain.exceptions.explain_exception` asks
here); runs wherever learner code does: the kernel and the judge's subjects.  Introduced in
``10-record-and-replay.ipynb``.
"""

from __future__ import annotations

import re
from typing import Optional

from .frames import frames_of, is_library_file, learner_frame

#: A ROS message type's name, as rosbags looks it up (``std_msgs/msg/Float64``).
_TYPE_NAME = re.compile(r'^\w+/msg/\w+$')
#: A /rosout line (``rcl_interfaces/msg/Log``) where a reading was meant.
_LOG_READ_AS_READING = re.compile(r"^'rcl_interfaces__msg__Log' object has no attribute '(\w+)'")


def bag_reading_mistake(exc: BaseException, text: str) -> Optional[str]:
    """The line for a bag read with the wrong type or the wrong connections, or None."""
    if isinstance(exc, KeyError) and exc.args and _TYPE_NAME.match(str(exc.args[0])) \
            and _raised_in_rosbags(exc):
        wanted = str(exc.args[0])
        held = _connections(exc)
        return (f"this bag holds no {wanted} messages ({held or 'see reader.connections'}): "
                'deserialize each message with the type its connection names, '
                'reader.deserialize(raw, connection.msgtype).')
    found = _LOG_READ_AS_READING.match(text) if isinstance(exc, AttributeError) else None
    if found:
        return (f'this message came from /rosout (rcl_interfaces/msg/Log: a log line, with no '
                f'{found.group(1)}): read only the /temperature connections, '
                "reader.messages([c for c in reader.connections if c.topic == '/temperature']).")
    return None


def _raised_in_rosbags(exc: BaseException) -> bool:
    frames = list(frames_of(exc))
    return bool(frames) and is_library_file(frames[-1].f_code.co_filename) \
        and 'rosbags' in frames[-1].f_code.co_filename


def _connections(exc: BaseException) -> str:
    """What the bag holds, as the learner's frame shows it: the reader's topics and types
    (``it holds /temperature: std_msgs/msg/Float32, ...``), or, once the reader is closed
    (the error left its ``with`` block), the connection being read; '' when neither is there.
    """
    frame = learner_frame(exc)
    values = list(frame.f_locals.values()) if frame is not None else []
    held: set[tuple[str, str]] = set()
    for value in values:
        if hasattr(value, 'connections') and hasattr(value, 'deserialize'):
            try:
                held |= {(c.topic, c.msgtype) for c in value.connections}
            except Exception:  # a reader of another library: no list, just the fix
                continue
    if held:
        return 'it holds ' + ', '.join(f'{topic}: {msgtype}' for topic, msgtype in sorted(held))
    read = sorted({(value.topic, value.msgtype) for value in values
                   if isinstance(getattr(value, 'topic', None), str)
                   and isinstance(getattr(value, 'msgtype', None), str)})
    return ', '.join(f'its connection {topic} holds {msgtype}' for topic, msgtype in read)
