"""One judge process's session: its observer, its subjects, its builds, its scratch folder.

Part of the judge (:mod:`ros2nb.judge`).  The checks get the session as their judge
(:class:`ros2nb.checks.base.Judge`) and ask it for subjects, programs and the observer.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any, Callable, Optional

from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float32

from .. import course
from ..checks.base import AnswerRef, learner_error
from ..checks.nodes import parts_verdict
from ..errors import CheckFailed
from ..processes import kill_process_group
from .observer import Observer
from .subjects import (Output, SubjectHung, SubjectProcess, home_and_tmp, subject_env,
                       subject_prefix, subjects_folder)


#: ``python -I -c SET_ENV_AND_EXEC ENV_JSON PROGRAM ARGS...``: PROGRAM (looked up on the
#: PATH of ENV) with exactly that environment, from inside a subject's sandbox.
SET_ENV_AND_EXEC = ('import json, os, sys; env = json.loads(sys.argv[1]); '
                    'os.execvpe(sys.argv[2], sys.argv[2:], env)')


class Session:
    """Everything one judge process shares between checks: observer, subjects, builds."""

    def __init__(self, workspace: Path) -> None:
        self.workspace = workspace
        shared = subjects_folder()
        self.scratch = Path(tempfile.mkdtemp(prefix='ros2nb-judge-',
                                             dir=home_and_tmp(shared)[1] if shared else None))
        self._observer: Optional[Observer] = None
        self._subjects: dict[tuple, SubjectProcess] = {}
        self._probe: Any = None
        self.builds: dict[str, Any] = {}

    @property
    def observer(self) -> Observer:
        if self._observer is None:
            self._observer = Observer()
        return self._observer

    @property
    def probe_publisher(self) -> Any:
        """The judge's own Float32 publisher on /temperature (it plays the sensor)."""
        if self._probe is None:
            self._probe = self.observer.node.create_publisher(
                Float32, '/' + course.TOPIC,
                QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
        return self._probe

    def subject(self, key: tuple, load: Callable[[SubjectProcess], None]) -> SubjectProcess:
        """A subject for ``key``, started and loaded once per session."""
        subject = self._subjects.get(key)
        if subject is None or subject.proc.poll() is not None:
            subject = SubjectProcess(self.workspace)
            self._subjects[key] = subject
            try:
                load(subject)
            except BaseException:
                self.drop(key)
                raise
        return subject

    def drop(self, key: tuple) -> None:
        subject = self._subjects.pop(key, None)
        if subject is not None:
            subject.close()

    def drop_all(self) -> None:
        """End every subject of this session (their nodes leave the graph)."""
        for key in list(self._subjects):
            self.drop(key)

    def subject_env(self) -> dict[str, str]:
        """The environment of a subject of this judge (its domain, plain logs, field checks)."""
        return subject_env()

    def file_subject(self, relative: str) -> SubjectProcess:
        """A subject with the learner's file imported (``relative`` to the workspace)."""
        path = self.workspace / relative

        def load(subject: SubjectProcess) -> None:
            reply = subject.request('load_file', path=str(path), module=path.stem)
            if reply.get('missing'):
                raise CheckFailed(f'{path.name} does not exist yet: run the %%part cells that '
                                  'write it, from part 1 on.')
            if not reply['ok']:
                parts_verdict(self.workspace, relative)  # a part never run explains it best
                raise learner_error(path.name, reply['error'], context=' on import')

        return self.subject(('file', relative), load)

    def answer_subject(self, ref: AnswerRef) -> SubjectProcess:
        """A subject with the course's context cells and the learner's answer cells run."""
        def load(subject: SubjectProcess) -> None:
            subject.request('exec_cells', sources=list(ref.sources))

        return self.subject(('cells', ref.sources), load)

    def start(self, argv: list[str], *, cwd: Path,
              env: Optional[dict[str, str]] = None) -> tuple[subprocess.Popen, Output]:
        """Start a program of the learner's (sandboxed while grading) in a session of its own.

        :param env: the program's whole environment (default :func:`subject_env`).  While
            grading it is set inside the sandbox, never on the sandbox's own command: an
            environment a learner's build gave (``PATH``, ``LD_PRELOAD``) must not choose or
            load the program that sandboxes theirs.
        :return: the process, and its output (stdout and stderr), collected as it comes.
        """
        prefix = subject_prefix()
        if prefix and env is not None:
            argv = [sys.executable, '-I', '-c', SET_ENV_AND_EXEC, json.dumps(env), *argv]
            env = None
        proc = subprocess.Popen([*prefix, *argv], cwd=cwd, env=env or subject_env(),
                                text=True, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, start_new_session=True)
        return proc, Output(proc.stdout)

    def run(self, argv: list[str], *, seconds: float, cwd: Path,
            env: Optional[dict[str, str]] = None) -> tuple[int, str]:
        """Run a program of the learner's (sandboxed while grading); return code and output."""
        proc, output = self.start(argv, cwd=cwd, env=env)
        try:
            code = proc.wait(seconds)
        except subprocess.TimeoutExpired:
            code = kill_process_group(proc)
            raise SubjectHung(f'{Path(argv[-1]).name} did not finish within {seconds:g} s.') \
                from None
        return code, output.text()

    def close(self) -> None:
        self.drop_all()
        if self._observer is not None:
            self._observer.close()
        shutil.rmtree(self.scratch, ignore_errors=True)
