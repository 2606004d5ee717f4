"""What the course's own code in a subject told the judge, on the judge's witness topic.

Part of :mod:`ros2nb.checks` (used by :mod:`.lesson06` and :mod:`.lesson07`, introduced in
``06-five-promises.ipynb``).  A line the learner's code logs is a line any code can print; where
a part is graded by what the learner's code makes the course's given code do, the subject runs
the course's version of that code (:mod:`ros2nb.subject.shown`), which publishes what happened
here.  The judge draws a token for each check run and sends it only after the learner's code
was loaded: only messages with that token count, so one the learner's code publishes on the
topic itself is not taken for the course's.
"""

from __future__ import annotations

import json
import secrets
from typing import Any

from std_msgs.msg import String

from ..judge_interface import Judge

#: The topic the course's code in a subject tells the judge on.
WITNESS_TOPIC = '/ros2nb/witness'


def new_token() -> str:
    """A token no code can know before the judge sends it (fresh for every check run)."""
    return secrets.token_hex(16)


def told_to(judge: Judge) -> list:
    """The judge's list of what arrives on :data:`WITNESS_TOPIC` (watched from now on)."""
    return judge.observer.watch(WITNESS_TOPIC, String, lambda msg: msg.data)


def told(heard: list, start: int, token: str) -> list[dict[str, Any]]:
    """The messages of ``heard`` from position ``start`` on that carry ``token``, decoded,
    in order of arrival; anything else on the topic is left out."""
    found = []
    for message in heard[start:]:
        try:
            fact = json.loads(message.value)
        except (TypeError, ValueError):
            continue
        if isinstance(fact, dict) and fact.get('token') == token and \
                isinstance(fact.get('event'), str):
            found.append(fact)
    return found


def events(heard: list, start: int, token: str) -> list[str]:
    """The events (e.g. ``'start'``) of :func:`told`, in order."""
    return [fact['event'] for fact in told(heard, start, token)]
