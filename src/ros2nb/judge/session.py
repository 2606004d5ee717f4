"""One judge process's session: its observer, its subjects, its builds, its scratch folder.

Part of the judge (:mod:`ros2nb.judge`).  The checks get the session as their judge
(:class:`ros2nb.judge_interface.Judge`) and ask it for subjects, programs and the observer.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path
from typing import Any, Callable, ContextManager, Optional

from rclpy.publisher import Publisher
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Bool, Float32

from .. import course, working
from ..checks.drawn import new_seed
from ..errors import CheckFailed
from ..processes import Process, kill_process_group, wait_patiently
from ..subject.judge_time import JUDGE_TOPICS_ENV
from ..subject.forked import fork_program
from ..temporary import owned_folder
from ..terminal.files import parts_verdict
from ..terminal.workspace import WORKSPACE_ENV
from . import handed
from .clock import JudgeClock
from ..judge_interface import AnswerRef, learner_error
from ..subject_interface import ExecCells, LoadFile, StandIns
from .observer import Observer
from .reaching import Reaching
from .stand_ins import source_of
from .written import workspace_files
from .subjects import (Output, SubjectHung, SubjectProcess, home_and_tmp, subject_env,
                       subject_prefix, subjects_folder)


#: ``python -I -c SET_ENV_AND_EXEC ENV_JSON PROGRAM ARGS...``: PROGRAM (looked up on the
#: PATH of ENV) with exactly that environment, from inside a subject's sandbox.
SET_ENV_AND_EXEC = ('import json, os, sys; env = json.loads(sys.argv[1]); '
                    'os.execvpe(sys.argv[2], sys.argv[2:], env)')


#: The course's reference node files (the judge's to read; a subject sees only the copies
#: :meth:`Session.answers_workspace` hands it).
reference_files = resources.files('ros2nb.reference')


class Session:
    """Everything one judge process shares between checks: observer, subjects, builds."""

    def __init__(self, workspace: Path, seed: Optional[int] = None) -> None:
        self.workspace = workspace
        #: the seed of this run's drawn inputs (:mod:`ros2nb.checks.drawn`): a grading run's,
        #: or a fresh one, drawn here, after the subjects' fork server started.
        self.seed = new_seed() if seed is None else seed
        shared = subjects_folder()
        self.scratch = owned_folder('ros2nb-judge-', home_and_tmp(shared)[1] if shared else None)
        # Opened before any subject runs: what the judge writes there for them goes through
        # this descriptor, never through a path a subject may have changed since.
        self._scratch_fd = os.open(self.scratch, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
        self._observer: Optional[Observer] = None
        self._clock: Optional[JudgeClock] = None
        self._subjects: dict[tuple[Any, ...], SubjectProcess] = {}
        self._programs: list[Process] = []  # the learner's programs (start, start_program)
        self._probe: Optional[Publisher] = None
        self.builds: dict[str, Path] = {}
        #: What the learner's code reached for in the subjects (their audit hooks): flags,
        #: and a failed check where it can only serve cheating (:mod:`.reaching`).
        self.reaching = Reaching(self._subjects)

    @property
    def observer(self) -> Observer:
        """The judge's own ROS node (made on first use, hearing the course's topics)."""
        if self._observer is None:
            self._observer = Observer()
            self._observer.attending = self.working_pids
            self._observer.floods.on_flood = self._end_flood
            # The course's topics are heard from the start, before any subject: what a
            # subject announces it published there is waited for before each step of the
            # clock (JudgeClock.drive), so every message is stamped with the step it came in.
            self._observer.watch('/' + course.TOPIC, Float32, lambda m: float(m.data))
            self._observer.watch('/' + course.FAN_TOPIC, Bool, lambda m: bool(m.data))
        return self._observer

    @property
    def clock(self) -> JudgeClock:
        """The judge's clock: the only simulated time the learner's nodes run on."""
        if self._clock is None:
            self._clock = JudgeClock(self.observer)
        return self._clock

    @property
    def probe_publisher(self) -> Publisher:
        """The judge's own Float32 publisher on /temperature (it plays the sensor)."""
        if self._probe is None:
            self._probe = self.observer.node.create_publisher(
                Float32, '/' + course.TOPIC,
                QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
        return self._probe

    def subject(self, key: tuple[Any, ...], load: Callable[[SubjectProcess], None],
                workspace: Optional[Path] = None) -> SubjectProcess:
        """A subject for ``key``, started and loaded once per session (in ``workspace``, by
        default the learner's)."""
        subject = self._subjects.get(key)
        if subject is None or subject.proc.poll() is not None:
            if subject is not None:  # it ended: what it saw stays (reaching)
                self._end(key)
            _ = self.clock  # published before any subject runs: it starts on the judge's time
            where = workspace or self.workspace
            heard = self.observer.counts()
            subject = SubjectProcess(where, env=subject_env({
                WORKSPACE_ENV: str(where), JUDGE_TOPICS_ENV: json.dumps(sorted(heard[0]))}))
            subject.heard_base = heard
            subject.while_waiting = self.observer.floods.raise_any
            self._subjects[key] = subject
            self.reaching.use(subject)
            try:
                load(subject)
            except BaseException:
                self._end(key)
                raise
        self.reaching.use(subject)
        return subject

    def working_pids(self) -> list[int]:
        """The processes of this session's subjects and of the learner's programs it started
        that still run: those whose work every wait of the judge's attends to."""
        self._programs = [proc for proc in self._programs if proc.poll() is None]
        return [proc.pid for proc in (*(s.proc for s in self._subjects.values()),
                                      *self._programs) if proc.poll() is None]

    def _end_flood(self) -> None:
        """End and reap every process that runs the learner's code now (one of them floods),
        before the flood is raised (:meth:`ros2nb.judge.floods.Floods.raise_any`); what runs
        next starts its subjects afresh."""
        for proc in (*(s.proc for s in self._subjects.values()), *self._programs):
            kill_process_group(proc)

    def drop(self, key: tuple[Any, ...]) -> None:
        """End the subject ``key``, and those of the same file with stand-ins (``key``
        followed by their names)."""
        for known in [k for k in self._subjects if k[:len(key)] == key]:
            self._end(known)

    def _end(self, key: tuple[Any, ...]) -> None:
        """End the subject ``key``; what its audit hook saw stays with :attr:`reaching`."""
        subject = self._subjects.pop(key)
        subject.close()
        self.reaching.keep(subject)

    def drop_all(self) -> None:
        """End every subject of this session (their nodes leave the graph)."""
        for key in list(self._subjects):
            self.drop(key)

    def subject_env(self) -> dict[str, str]:
        """The environment of a subject of this judge (its domain, plain logs, field checks)."""
        return subject_env()

    def file_subject(self, relative: str, stand_ins: tuple[str, ...] = ()) -> SubjectProcess:
        """A subject with the learner's file imported (``relative`` to the workspace), and the
        course's ``stand_ins`` (:mod:`.stand_ins`) compiled in it once the file is: one subject
        per set of stand-ins, so that no learner's code ever ran beside the course's version
        of the part it is graded on."""
        path = self.workspace / relative

        def load(subject: SubjectProcess) -> None:
            working.say(f'loading {path.name} in a process of its own')
            reply = subject.request(LoadFile(path=str(path), module=path.stem))
            if reply.missing:
                raise CheckFailed(f'{path.name} does not exist yet: run the %%part cells that '
                                  'write it, from part 1 on.')
            if not reply.ok:
                parts_verdict(self.workspace, relative)  # a part never run explains it best
                if reply.error is not None:
                    raise learner_error(path.name, reply.error, context=' on import')
                raise CheckFailed(f'{path.name} could not be imported: run this check again.')
            if stand_ins:
                subject.request(StandIns(source=source_of(stand_ins)))

        return self.subject(('file', relative, *(['+', *stand_ins] if stand_ins else [])),
                            load)

    def grade_as_written(self, files: dict[str, str]) -> None:
        """From now on, grade a copy of the workspace in which each of ``files`` (a path in the
        workspace -> its text) is written so: what the notebook's ``%%part`` cells write,
        where another cell changed the file (:mod:`.written`).  A workspace too large to copy
        is graded as it is."""
        found = workspace_files(self.workspace)
        if found is not None:
            found.update({relative: text.encode() for relative, text in files.items()})
            self.workspace = self.hand_over('as-written-', found)

    def answer_subject(self, ref: AnswerRef, workspace: Optional[Path] = None) -> SubjectProcess:
        """A subject with the course's context cells and the learner's answer cells run (in
        ``workspace``, by default the learner's)."""
        def load(subject: SubjectProcess) -> None:
            working.say('running your answer cells in a process of its own')
            subject.request(ExecCells(sources=list(ref.sources)))

        return self.subject(('cells', ref.sources, str(workspace)), load, workspace)

    def answers_workspace(self, steps: tuple[str, ...]) -> Path:
        """The workspace a notebook's answers run in: the learner's, or, when a node file the
        notebook relies on (``steps``, as :data:`ros2nb.course.STEPS` names them) is missing
        because the notebook was handed in alone, a copy with the course's reference node in
        its place: what ``catch_up`` promises a notebook run on its own.  The learner's own
        files are kept; a link is never followed (the reference stands in for it).
        """
        files = {step: relative for step, relative in (('publisher', course.PUBLISHER_FILE),
                                                     ('subscriber', course.SUBSCRIBER_FILE))
                 if step in steps}
        own = {relative: self.workspace / relative for relative in files.values()}
        if all(path.is_file() and not path.is_symlink() for path in own.values()):
            return self.workspace
        given = {}
        for relative, path in own.items():
            if path.is_file() and not path.is_symlink():
                given[relative] = path.read_bytes()
            else:
                given[relative] = reference_files.joinpath(Path(relative).name).read_bytes()
        return self.hand_over('caught-up-', given)

    def start(self, argv: list[str], *, cwd: Path,
              env: Optional[dict[str, str]] = None) -> tuple[subprocess.Popen[str], Output]:
        """Start a program of the learner's (sandboxed while grading) in a session of its own.

        :param env: the program's whole environment (default :func:`subject_env`).  While
            grading it is set inside the sandbox, never on the sandbox's own command: an
            environment a learner's build gave (``PATH``, ``LD_PRELOAD``) must not choose or
            load the program that sandboxes theirs.
        :return: the process, and its output (stdout and stderr), collected as it comes.
        """
        working.say(f'starting {Path(argv[0]).name}')
        prefix = subject_prefix()
        if prefix and env is not None:
            argv = [sys.executable, '-I', '-c', SET_ENV_AND_EXEC, json.dumps(env), *argv]
            env = None
        proc = subprocess.Popen([*prefix, *argv], cwd=cwd, env=env or subject_env(),
                                text=True, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, start_new_session=True)
        self._programs.append(proc)
        return proc, Output(proc.stdout)

    def start_program(self, path: Path, stand_in: Optional[str] = None
                      ) -> tuple[Process, Output]:
        """Start the learner's ``main()`` in ``path`` as ``ros2 run`` would, in the learner's
        workspace, as :mod:`ros2nb.subject.program` does it (its node class replaced by the
        course's stand-in ``stand_in`` when given): sandboxed while grading, else forked from
        the fork server (:mod:`ros2nb.subject.forked`), the process ``python -m`` would be.

        :return: the process, and its output (stdout and stderr), collected as it comes.
        """
        args = [str(path), *([stand_in] if stand_in else [])]
        working.say(f'starting main() of {path.name}, as ros2 run does')
        if subject_prefix():
            return self.start([sys.executable, '-m', 'ros2nb.subject.program', *args],
                              cwd=self.workspace)
        proc = fork_program(args, str(self.workspace), subject_env())
        self._programs.append(proc)
        return proc, Output(proc.stdout)

    def run(self, argv: list[str], *, seconds: float, cwd: Path,
            env: Optional[dict[str, str]] = None, what: Optional[str] = None) -> tuple[int, str]:
        """Run a program of the learner's (sandboxed while grading); return code and output.

        :param seconds: what the program gets (:func:`~ros2nb.processes.wait_patiently`):
            seconds of its work while it works, of the wall clock while it waits.
        :param what: the program as its failure names it (default: its file's name).
        :raises SubjectHung: when it had them and still runs.
        """
        proc, output = self.start(argv, cwd=cwd, env=env)
        working.say(f'running {what or Path(argv[0]).name}')
        code = wait_patiently(proc, seconds)
        if code is None:
            kill_process_group(proc)
            raise SubjectHung(f'{what or Path(argv[0]).name} did not finish within {seconds:g} s.')
        return code, output.text()

    def hand_over(self, prefix: str, files: dict[str, bytes]) -> Path:
        """A new folder in the scratch folder with ``files`` (a relative path, ``a/b.xml``, to
        its bytes) that the learner's code may read: the check's own inputs
        (:func:`.handed.hand_over`).

        :raises CheckFailed: when a name the judge was making was taken over meanwhile.
        """
        return handed.hand_over(self.scratch, self._scratch_fd, prefix, files)

    def taken_back(self, folder: Path) -> ContextManager[Path]:
        """A copy, in a temporary folder of the judge's own, of the files the learner's code
        left in ``folder``, a folder of the scratch folder (:func:`.handed.taken_back`).

        :raises CheckFailed: for a link, a folder or anything else that is not a file, or for
            too many bytes.
        """
        return handed.taken_back(self.scratch, self._scratch_fd, folder)

    def close(self, *, hurried: bool = False) -> None:
        """End the subjects and programs, the observer, and remove the scratch folder.

        :param hurried: the judge is being ended from outside (its kernel ended): the
            processes that run the learner's code are ended at once, not asked first, and
            the folder goes before the observer, in case the end comes sooner.
        """
        if hurried:
            self._end_flood()  # every process of the learner's code, ended and reaped now
        self.drop_all()
        if hurried:
            shutil.rmtree(self.scratch, ignore_errors=True)
        if self._observer is not None:
            self._observer.close()
        os.close(self._scratch_fd)
        shutil.rmtree(self.scratch, ignore_errors=True)
