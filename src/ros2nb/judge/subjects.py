"""The subject processes the judge starts to run the learner's code, and what it tells them.

Part of the judge (:mod:`ros2nb.judge`).  A subject (:mod:`ros2nb.subject`) imports the
learner's file or runs their answer cells; the judge sends it one JSON command at a time
on a pipe and reads one JSON reply.  While grading, every subject runs under the grader's
sandbox command (``ROS2NB_SUBJECT_PREFIX``) and cannot see, signal or trace the judge.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import select
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any, Callable, Optional, Sequence, TypeVar

from .. import domains
from ..errors import CheckFailed, NotDecided
from ..patience import Patience
from ..processes import kill_process_group, stop_process_group
from ..subject.judge_time import JUDGE_CLOCK_ENV, Acknowledgement, Waiting
from ..subject.forked import SUBJECT_PREFIX_ENV, fork_subject, has_server
from ..subject_interface import Command, reply_type, wire
from ..subject_replies import Reply
from ..typed_json import decoded
from .reaching import END, PER_KIND, SEEN_PREFIX, Reached, parse_count, parse_seen

#: The folder the judge keeps what its subjects and the learner's programs see (while
#: grading, given by the grader; else a temporary folder of the session's): the judge's
#: inputs for them, which they may read (``handed/``: builds, bags, files it feeds to the
#: learner's functions), and a folder of its own for each process (its home, its temporary
#: files, its working folder), which only that process may write and which goes when it ends
#: (:class:`ros2nb.judge.session.Session`).  The judge's own cwd, home and temporary files
#: stay out of their reach.
SUBJECTS_FOLDER_ENV = 'ROS2NB_SUBJECTS_FOLDER'
#: The part of :data:`SUBJECTS_FOLDER_ENV` the judge's subjects and programs may read (the
#: grader's sandbox shows them this one and each process its own folder, nothing else of it).
HANDED = 'handed'
#: Seconds a subject may take to answer one command before it counts as hanging: CPU
#: seconds while it works, wall-clock seconds while it waits (ros2nb.patience.Patience).
REPLY_TIMEOUT_S = 30.0
#: Seconds between two looks at a subject that has not answered yet.
POLL_S = 0.25
#: Lines of a subject's own output kept for hints.
KEPT_OUTPUT_LINES = 200
R = TypeVar('R', bound=Reply)
#: Subjects this process has started.  Unless sandboxed, they are forked from a server
#: that has imported ROS (:mod:`ros2nb.subject.forked`): all of them in a judge process,
#: which forks its server from itself as it starts; elsewhere all but the first, which
#: would not repay starting a server afresh (a test that starts one subject).
_STARTED = itertools.count()


def subject_prefix(writable: Sequence[Path] = ()) -> list[str]:
    """The sandbox command a subject or program runs under (empty outside grading), with
    ``writable`` (its own folder, and the judge's folders it is to write) bound for writing:
    nothing else of the judge's folder is writable, or visible but ``handed/``."""
    value = os.environ.get(SUBJECT_PREFIX_ENV)
    prefix = json.loads(value) if value else []
    if not prefix or prefix[-1] != '--':  # not bubblewrap's (a test's ``env``): as it is
        return prefix
    binds = [arg for path in writable for arg in ('--bind', str(path), str(path))]
    return [*prefix[:-1], *binds, prefix[-1]]  # before its closing '--'


def python_start() -> list[str]:
    """``python`` as a subject or program is started: isolated from its working folder
    (``-P``, Python 3.11 on; before, the subject takes that folder off ``sys.path`` itself,
    first thing), so that no module there stands in for the standard library's."""
    return [sys.executable, *(['-P'] if sys.version_info >= (3, 11) else [])]


def subjects_folder() -> Optional[Path]:
    """The folder of the judge's subjects (:data:`SUBJECTS_FOLDER_ENV`), if one is set."""
    value = os.environ.get(SUBJECTS_FOLDER_ENV)
    return Path(value) if value else None


def home_and_tmp(folder: Path) -> tuple[Path, Path]:
    """The home and temporary folder of a process in its own folder."""
    return folder / 'home', folder / 'tmp'


def subject_env(extra: Optional[dict[str, str]] = None,
                folder: Optional[Path] = None) -> dict[str, str]:
    """The environment of a subject or program: the judge's domain, field checks on, plain
    logs.

    With its own ``folder``, its ``HOME`` is that folder's ``home/`` (every variable the
    judge has under its own home moves there too: ROS's logs, IPython's and Jupyter's
    folders) and its ``TMPDIR`` is its ``tmp/``.
    """
    env = {k: v for k, v in os.environ.items()
           if k not in (SUBJECT_PREFIX_ENV, SUBJECTS_FOLDER_ENV)}
    own_home = os.environ.get('HOME', '')
    if folder is not None:
        home, tmp = home_and_tmp(folder)
        for name, value in env.items():
            if own_home and (value == own_home or value.startswith(own_home + os.sep)):
                env[name] = str(home) + value[len(own_home):]
        env['HOME'], env['TMPDIR'] = str(home), str(tmp)
    env.update({'ROS_DOMAIN_ID': str(domains.domain_id()), 'PYTHONUNBUFFERED': '1',
                'ROS_PYTHON_CHECK_FIELDS': '1', 'RCUTILS_COLORIZED_OUTPUT': '0',
                'RCUTILS_CONSOLE_OUTPUT_FORMAT': '[{severity}] [{name}]: {message}'})
    env.update(extra or {})  # discovery range and transports: the judge's own
    return env


class Output:
    """The last lines a process printed, read in a thread of their own."""

    def __init__(self, stream: Any) -> None:
        self.lines: list[str] = []
        self._thread = threading.Thread(target=self._read, args=(stream,), daemon=True)
        self._thread.start()

    def _read(self, stream: Any) -> None:
        for line in stream:
            self.lines.append(line.rstrip('\n'))
            del self.lines[:-KEPT_OUTPUT_LINES]

    def text(self) -> str:
        self._thread.join(0.5)
        return '\n'.join(self.lines)


def _acknowledgement(line: bytes) -> Acknowledgement:
    """An acknowledgement as :class:`~ros2nb.subject.judge_time.JudgeTime` writes it.

    :raises ros2nb.typed_json.Unreadable: for JSON of another shape, naming the field.
    :raises ValueError: for a line that is no JSON.
    """
    ack: Acknowledgement = decoded(Acknowledgement, json.loads(line))
    return ack


def _waiting(line: bytes) -> Optional[str]:
    """What a subject says it waits for (:class:`~ros2nb.subject.judge_time.Waiting`), or
    None (also for a line of another shape)."""
    try:
        said: Waiting = decoded(Waiting, json.loads(line))
    except ValueError:  # no JSON, or Unreadable (a ValueError)
        return None
    return said.waiting[:80] if said.waiting is not None else None


class SubjectHung(CheckFailed):
    """The learner's code did not answer in time."""


class SubjectProcess:
    """A running ``ros2nb.subject``: one JSON command, one JSON reply; and, while its nodes
    run on the judge's clock, one acknowledgement per step (:mod:`ros2nb.judge.clock`)."""

    def __init__(self, cwd: Path, env: Optional[dict[str, str]] = None,
                 writable: Sequence[Path] = ()) -> None:
        """Start a subject in ``cwd`` (a folder of its own: it may write there), with ``env``
        (default :func:`subject_env`); while grading, ``writable`` are the folders its sandbox
        lets it write (its own, and those the judge gives it to write into)."""
        to_subject, self._commands = os.pipe()
        self._replies, from_subject = os.pipe()
        self._acks, acks_from_subject = os.pipe()
        os.set_blocking(self._acks, False)
        prefix, environment = subject_prefix(writable), env or subject_env()
        first = next(_STARTED) == 0
        try:
            if prefix or (first and not has_server()):  # sandboxed, or the first: afresh
                argv = [*prefix, *python_start(), '-m', 'ros2nb.subject', str(to_subject),
                        str(from_subject)]
                self.proc: Any = subprocess.Popen(
                    argv, cwd=cwd, env={**environment, JUDGE_CLOCK_ENV: str(
                        acks_from_subject)}, text=True, stdin=subprocess.DEVNULL,
                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True,
                    pass_fds=(to_subject, from_subject, acks_from_subject))
            else:  # forked from a process that has imported ROS: no imports of its own
                self.proc = fork_subject((to_subject, from_subject, acks_from_subject),
                                         str(cwd), environment, JUDGE_CLOCK_ENV)
        finally:
            for fd in (to_subject, from_subject, acks_from_subject):
                os.close(fd)
        self.output = Output(self.proc.stdout)
        self._buffer = b''
        self._ack_buffer = b''
        #: The newest well-formed acknowledgement of a step (None before the first).
        self.last_ack: Optional[Acknowledgement] = None
        #: What the subject last said it waits for on the judge's side (the judge's clock,
        #: :data:`~ros2nb.subject.judge_time.WAITING_FOR_CLOCK`), or None: idle there, it is
        #: not the learner's code that hangs.
        self.waiting_for: Optional[str] = None
        #: What the learner's code reached for, as the subject's audit hook wrote it on the
        #: same pipe (:mod:`ros2nb.judge.reaching`), in order: each kind's first places.
        self.seen: list[Reached] = []
        #: Each kind's count of events, as the hook told it (past its places, and at the end).
        self.seen_counts: dict[str, int] = {}
        #: Whether the hook's last line came (:data:`~ros2nb.judge.reaching.END`).
        self.seen_ended = False
        #: Whether the subject ended as asked without that line: its channel was cut.
        self.channel_lost = False
        #: What the judge had heard when this process started: messages per watched topic,
        #: /rosout lines per logger (set by the session that starts it).
        self.heard_base: tuple[dict[str, int], dict[str, int]] = ({}, {})
        #: Called while :meth:`request` waits for a reply, before each look: raises to stop
        #: waiting (the session's: a flood found ends the subjects and fails the check).
        self.while_waiting: Callable[[], None] = lambda: None

    def send(self, command: Command[Any]) -> None:
        """Send one command (its reply comes later: :meth:`poll_reply`, read with
        :meth:`reply_to`)."""
        try:
            os.write(self._commands, (json.dumps(wire(command)) + '\n').encode())
        except BrokenPipeError:
            raise self._died() from None

    @staticmethod
    def reply_to(command: Command[R], data: Any) -> R:
        """A reply as :meth:`poll_reply` read it, as ``command``'s reply type.

        :raises ros2nb.typed_json.Unreadable: when it does not fit that type (the subject
            runs learner code, which may write anything there): that check fails alone.
        """
        reply: R = decoded(reply_type(type(command)), data)
        return reply

    def poll_reply(self, seconds: float) -> Any:
        """The reply as JSON, if it has come within ``seconds``; else None.

        :raises CheckFailed: when the process ended (its last output line says why).
        """
        if b'\n' not in self._buffer:
            ready, _, _ = select.select([self._replies, self._acks], [], [], seconds)
            if self._replies in ready:
                chunk = os.read(self._replies, 65536)
                if not chunk:
                    raise self._died()
                self._buffer += chunk
        if b'\n' not in self._buffer:
            return None
        line, self._buffer = self._buffer.split(b'\n', 1)
        return json.loads(line)

    def take_ack(self) -> Optional[Acknowledgement]:
        """The newest acknowledgement that came since the last call (None if none came).

        Lines that are not well formed (:class:`~ros2nb.typed_json.Unreadable`) are skipped:
        the process runs learner code, which may write anything there; what it says only
        tells the judge when to step and what to wait for.  What the subject's audit hook
        wrote there goes to :attr:`seen`.
        """
        newest = None
        for line in self._pipe_lines():
            try:
                newest = _acknowledgement(line)
            except ValueError:  # Unreadable (a ValueError), or no JSON
                if line.startswith(b'{"waiting"'):
                    self.waiting_for = _waiting(line)
        if newest is not None:
            self.last_ack = newest
        return newest

    def take_seen(self) -> list[Reached]:
        """Everything the subject's audit hook wrote so far (:attr:`seen`), read without taking
        an acknowledgement: those stay for the clock (:meth:`take_ack`)."""
        kept = self._pipe_lines()
        self._ack_buffer = b''.join(line + b'\n' for line in kept) + self._ack_buffer
        return self.seen

    def _pipe_lines(self) -> list[bytes]:
        """The whole lines that came on the pipe since the last call, but the audit hook's
        (which go to :attr:`seen`)."""
        try:
            while chunk := os.read(self._acks, 65536):
                self._ack_buffer += chunk
        except (BlockingIOError, OSError):
            pass
        *lines, self._ack_buffer = self._ack_buffer.split(b'\n')
        kept = []
        for line in lines:
            if not line.startswith(SEEN_PREFIX):
                kept.append(line)
                continue
            reached, counted = parse_seen(line), parse_count(line)
            if reached is not None and \
                    sum(event.kind == reached.kind for event in self.seen) < PER_KIND:
                self.seen.append(reached)
            elif counted is not None:
                for kind, total in counted.counts.items():
                    self.seen_counts[kind] = max(total, self.seen_counts.get(kind, 0))
                self.seen_ended = self.seen_ended or counted.kind == END
        return kept

    def request(self, command: Command[R], *, timeout: float = REPLY_TIMEOUT_S) -> R:
        """Send one command and return its reply (``command``'s reply type).

        :param timeout: seconds the subject gets: of CPU time while it works, of the wall
            clock while it waits (:class:`~ros2nb.patience.Patience`), so that a busy
            machine never turns slow honest work into a hang.
        :raises SubjectHung: when no reply comes within ``timeout`` seconds, or the
            process died (its last output line is in the message).
        :raises NotDecided: when it sat idle that long waiting for the judge's side (its
            clock: :attr:`waiting_for`).
        :raises Exception: what :attr:`while_waiting` raises (the session's:
            :class:`~ros2nb.judge_interface.Flooded`).
        :raises ros2nb.typed_json.Unreadable: for a reply that does not fit its type.
        """
        self.send(command)
        sent, patience = time.monotonic(), None
        while True:
            # A flood heard meanwhile ends the wait at once: its CPU-seconds would otherwise
            # count as this subject's work, and on a busy machine run out its patience
            # before the reply, so that the learner's line would depend on the machine.
            self.while_waiting()
            reply = self.poll_reply(POLL_S)
            self.take_ack()
            if reply is not None:
                return self.reply_to(command, reply)
            # No reply within POLL_S: from now on the subject's CPU time counts.  (Most
            # replies come sooner, and reading /proc for each cost the judge more than the
            # reply.)
            if patience is None:
                patience = Patience(self.proc.pid, timeout, started=sent)
            elif patience.exhausted():
                raise self.ran_out(patience, timeout)

    def ran_out(self, patience: Patience, timeout: float) -> Exception:
        """End this subject, which had its ``patience`` (of ``timeout`` seconds); the error to
        raise for it: :class:`NotDecided` when it sat idle waiting for the judge's side
        (:attr:`waiting_for`), else :meth:`given_up`'s."""
        self.take_ack()  # what it said last
        if patience.ran_out_idle and self.waiting_for is not None:
            kill_process_group(self.proc)
            return NotDecided(f'{self.waiting_for} never reached the process that runs your code')
        return self.given_up(timeout)

    def given_up(self, timeout: float) -> SubjectHung:
        """End this subject, which used up ``timeout`` seconds; the error to raise for it."""
        kill_process_group(self.proc)
        return SubjectHung(f'Your code did not finish within {timeout:g} s (an endless loop, or '
                           'a call that waits for ever?): look for a loop that never ends in the '
                           'part you wrote.')

    def _died(self) -> CheckFailed:
        code = self.proc.wait(5)
        last = [line for line in self.output.text().splitlines() if line.strip()][-1:]
        return CheckFailed(f'The process running your code ended (exit code {code})'
                           + (f': {last[0].strip()}' if last else '') +
                           ' (does your code call exit() or kill its own process?).')

    def close(self) -> None:
        with contextlib.suppress(OSError):
            os.write(self._commands, b'{"op": "quit"}\n')
        with contextlib.suppress(OSError):
            os.close(self._commands)
        try:
            self.proc.wait(5)
        except subprocess.TimeoutExpired:
            pass
        stop_process_group(self.proc)
        self.take_seen()  # what its audit hook wrote last
        # It ended as asked, on ``quit``, yet its hook's last line never came: something in it
        # closed or redirected the pipe (a note).  A subject the judge ended says nothing:
        # sandboxed, the exit code is its sandbox's, whose end kills it at once.
        self.channel_lost = not self.seen_ended and self.proc.returncode == 0
        for fd in (self._replies, self._acks):
            with contextlib.suppress(OSError):
                os.close(fd)
