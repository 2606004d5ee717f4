"""What the course's own code in a subject told the judge, on the judge's witness topic.

Part of :mod:`ros2nb.checks` (used by :mod:`.lesson06_worker` and :mod:`.lesson07`, introduced in
``06-five-promises.ipynb``).  A line the learner's code logs is a line any code can print, and
anything in the subject's process its code can reach, so nothing told here is believed as
it is said (:mod:`ros2nb.subject.shown`):

- notebook 06: ``started NONCE`` only says that the course's slow work began on the request
  that carried that nonce (drawn here, known only to the request); what decides is the
  answers the judge times itself;
- notebook 07: ``drawn SEQ;TIMES;TEMPS;MAC`` counts only with the seal of the subject's key
  (:attr:`ros2nb.judge.subjects.SubjectProcess.seal`), which the judge sent before the
  learner's code was loaded: anything else on the topic is left out.
"""

from __future__ import annotations

import hashlib
import hmac
import secrets
from typing import Any, Optional

from std_msgs.msg import String

from ..judge_interface import Judge

#: The topic the course's code in a subject tells the judge on.
WITNESS_TOPIC = '/ros2nb/witness'


def new_nonce() -> str:
    """A value no code can know before the judge sends it (fresh for every request)."""
    return secrets.token_hex(16)


def told_to(judge: Judge) -> list:
    """The judge's list of what arrives on :data:`WITNESS_TOPIC` (watched from now on)."""
    return judge.observer.watch(WITNESS_TOPIC, String, lambda msg: msg.data)


def started(heard: list, start: int, nonce: str) -> bool:
    """Whether ``started NONCE`` arrived from position ``start`` on."""
    return any(message.value == f'started {nonce}' for message in heard[start:])


def _numbers(text: str) -> list[Optional[float]]:
    """``1.5,x,2.0`` -> ``[1.5, None, 2.0]`` (``x``: what was no number)."""
    found: list[Optional[float]] = []
    for part in text.split(',') if text else []:
        try:
            found.append(None if part == 'x' else float(part))
        except ValueError:
            found.append(None)
    return found


def sealed(heard: list, start: int, key: str) -> list[dict[str, Any]]:
    """The drawings that arrived from position ``start`` on with the seal of ``key``, in the
    order they were sealed, each once: ``{'times_s': [...], 'temps_c': [...]}``."""
    found, last = [], 0
    for message in heard[start:]:
        text = message.value if isinstance(message.value, str) else ''
        payload, _, mac = text.removeprefix('drawn ').rpartition(';')
        good = hmac.new(key.encode(), payload.encode(), hashlib.sha256).hexdigest()
        count, _, lists = payload.partition(';')
        if not (text.startswith('drawn ') and hmac.compare_digest(mac, good)
                and count.isdigit() and int(count) > last):
            continue
        last = int(count)
        times, _, temps = lists.partition(';')
        found.append({'times_s': _numbers(times), 'temps_c': _numbers(temps)})
    return found
