"""Hand a notebook in, on the course's hub: the server records the time, not your computer.

``ros2nb.hand_in("03")`` sends your notebook ``03-...ipynb`` as last saved to the hub's
hand-in service, which keeps a copy and the time by its own clock in a place only your
instructor can change (:mod:`ros2nb_instructor.hub.hand_in_service`); each notebook has its
own hand-in time, and handing one in again replaces that copy and its time.  Outside the
hub (``make lab``, the image) there is no such service: hand in through your course's
platform, whose clock counts there.

The service's answers are typed here, once (:class:`NotebookStatus`, :class:`Standing`):
the service writes them, the kernel reads them back with :mod:`ros2nb.typed_json`.  No ROS
import.  Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` ("Your progress").
"""

from __future__ import annotations

import datetime
import json
import os
import urllib.error
import urllib.request
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Union

from .errors import Ros2nbError
from .graded_parts import NOTEBOOKS, WORK_ENV
from .typed_json import Unreadable, decoded

#: Where the hub's hand-in service listens, as the learner's server is told (the hub's config).
URL_ENV = 'ROS2NB_HAND_IN_URL'
#: The learner's own token on the hub (JupyterHub gives every server and its kernels one).
TOKEN_ENV = 'JUPYTERHUB_API_TOKEN'
#: Seconds to wait for the service's answer (it writes one file).
ANSWER_S = 60
#: The header the file's modification time travels in (shown to the learner, never graded).
SAVED_HEADER = 'X-Ros2nb-Saved'


class HandInError(Ros2nbError):
    """A notebook could not be handed in; the message says what to do next."""


@dataclass(frozen=True)
class NotebookStatus:
    """What the hub knows of one of your notebooks (times in ISO 8601 with their offset).

    :ivar handed_in: when you last handed it in, by the hub's clock; None: never.
    :ivar saved: when the file you handed in was last saved (its modification time).
    :ivar due: your due date (your extension's, if you have one); None: not due.
    :ivar class_due: the class's due date where yours is an extension, else None.
    :ivar late_by: how late the hand-in was, in words ('' when on time or not handed in).
    :ivar feedback: whether your instructor released a feedback page for it.
    """

    notebook: str
    handed_in: Optional[str] = None
    saved: Optional[str] = None
    due: Optional[str] = None
    class_due: Optional[str] = None
    late_by: str = ''
    feedback: bool = False


@dataclass(frozen=True)
class Standing:
    """Your notebooks as the hub's hand-in service knows them.

    :ivar feedback_url: where your feedback pages are, on the hub (a path of its address).
    """

    learner: str
    notebooks: tuple[NotebookStatus, ...]
    feedback_url: str


def notebook_name(notebook: Union[str, int]) -> str:
    """The course notebook ``notebook`` names: ``3``, ``"03"``, ``"03-write-the-publisher"``
    or its file name.

    :raises HandInError: for a name that is no notebook of the course.
    """
    text = str(notebook).removesuffix('.ipynb')
    if text.isdigit():
        text = f'{int(text):02d}'
    names = sorted(p.stem for p in NOTEBOOKS.glob('[0-9][0-9]-*.ipynb'))
    found = [n for n in names if text in (n, n[:2])]
    if len(found) != 1:
        raise HandInError(f'{notebook!r} is no notebook of the course: write its number, such '
                          f'as ros2nb.hand_in("03")')
    return found[0]


def _service() -> Optional[tuple[str, str]]:
    """The hand-in service's address and the learner's token, or None outside the hub."""
    url, token = os.environ.get(URL_ENV), os.environ.get(TOKEN_ENV)
    return (url.rstrip('/') + '/', token) if url and token else None


def _ask(method: str, path: str, body: Optional[bytes] = None,
         headers: Optional[dict[str, str]] = None) -> object:
    """The service's JSON answer to ``method path`` (with ``body`` and ``headers``).

    :raises HandInError: when there is no service, it does not answer, or refuses.
    """
    service = _service()
    if service is None:
        raise HandInError('This lab is not on the course\'s hub, so there is no hand-in '
                          'server here: hand your notebook in through your course\'s platform')
    url, token = service
    request = urllib.request.Request(url + path, data=body, method=method, headers={
        'Authorization': f'token {token}', 'Content-Type': 'application/x-ipynb+json',
        **(headers or {})})
    try:
        with urllib.request.urlopen(request, timeout=ANSWER_S) as answer:
            return json.loads(answer.read())
    except urllib.error.HTTPError as error:
        said = error.read()[:300].decode('utf-8', 'replace').strip()
        raise HandInError(f'The hand-in server refused ({error.code}): {said or error.reason}'
                          ) from None
    except (OSError, ValueError) as error:
        raise HandInError(f'The hand-in server did not answer ({error}): try again in a '
                          'minute; if it keeps failing, tell your instructor') from None


def hand_in(notebook: Union[str, int]) -> None:
    """Hand in your notebook ``notebook`` as last saved (save it first: Ctrl+S), and print
    when the hub recorded it and how that compares with your due date.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param notebook: its number (``"03"`` or ``3``) or name.
    :raises HandInError: outside the hub, for a notebook that is not in your work folder,
        or when the hub refuses or does not answer; the message says what to do.
    """
    name = notebook_name(notebook)
    path = Path(os.environ.get(WORK_ENV) or Path.cwd()).expanduser() / f'{name}.ipynb'
    try:
        data = path.read_bytes()
        saved = datetime.datetime.fromtimestamp(path.stat().st_mtime).astimezone()
    except OSError:
        raise HandInError(f'{path} is not there: open and save {name}.ipynb in your work '
                          'folder, then hand it in') from None
    try:
        status = decoded(NotebookStatus, _ask('POST', f'api/hand-ins/{name}', data,
                                              {SAVED_HEADER: saved.isoformat()}))
    except Unreadable as error:
        raise HandInError(f'The hand-in server answered something else ({error}): tell your '
                          'instructor') from None
    print(said(status))


def standing() -> Optional[Standing]:
    """What the hub's hand-in service knows of your notebooks; None outside the hub.

    :raises HandInError: when the service does not answer, or answers something else.
    """
    if _service() is None:
        return None
    try:
        return decoded(Standing, _ask('GET', 'api/hand-ins'))
    except Unreadable as error:
        raise HandInError(f'The hand-in server answered something else ({error}): tell your '
                          'instructor') from None


def _time(text: Optional[str], zone: Optional[datetime.tzinfo] = None) -> str:
    """An ISO time as shown: to the second, in ``zone`` (the due date's) when given."""
    if not text:
        return ''
    when = datetime.datetime.fromisoformat(text)
    return (when.astimezone(zone) if zone else when).isoformat(sep=' ', timespec='seconds')


def due_line(status: NotebookStatus) -> str:
    """When a notebook is due and was handed in, in one line ('' when it has no due date
    and was never handed in)."""
    zone = datetime.datetime.fromisoformat(status.due).tzinfo if status.due else None
    parts = []
    if status.due:
        extension = f' (your extension; the class\'s: {_time(status.class_due)})' \
            if status.class_due else ''
        parts.append(f'due {_time(status.due)}{extension}')
    if status.handed_in:
        when = (f'late by {status.late_by}' if status.late_by
                else 'on time' if status.due else '')
        parts.append(f'handed in {_time(status.handed_in, zone)}' + (f': {when}' if when else ''))
    elif status.due:
        parts.append('not handed in yet')
    return '; '.join(parts)


def said(status: NotebookStatus) -> str:
    """The line :func:`hand_in` prints."""
    saved = f', as saved at {_time(status.saved)}' if status.saved else ''
    return (f'Handed in {status.notebook} by the hub\'s clock{saved}. '
            f'{due_line(status)[:1].upper()}{due_line(status)[1:]}.')
