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
import tempfile
from importlib import resources
from pathlib import Path
from typing import Any, Callable, ContextManager, Optional, Sequence

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
from .subjects import (HANDED, Output, SubjectHung, SubjectProcess, home_and_tmp, python_start,
                       subject_env, subject_prefix, subjects_folder)


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
        # What the subjects and programs see of the judge's (SUBJECTS_FOLDER_ENV): its inputs
        # for them, which they read (``handed/``), and a folder of each one's own, which only
        # it writes and which goes when it ends: nothing one of them wrote reaches the next.
        shared = subjects_folder()
        self._top = shared or owned_folder('ros2nb-judge-')
        self._own_top = shared is None
        (self._top / HANDED).mkdir(mode=0o755, exist_ok=True)
        self.scratch = Path(tempfile.mkdtemp(prefix='ros2nb-judge-', dir=self._top / HANDED))
        self.scratch.chmod(0o755)
        # Opened before any subject runs: what the judge writes there for them goes through
        # this descriptor, never through a path a subject may have changed since.
        self._scratch_fd = os.open(self.scratch, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
        #: Folders of the judge's the learner's code is to write into now (a bag), given to
        #: the subjects and programs started while they are open (:meth:`fresh_folder`).
        self._outboxes: list[Path] = []
        self._observer: Optional[Observer] = None
        self._clock: Optional[JudgeClock] = None
        self._subjects: dict[tuple[Any, ...], SubjectProcess] = {}
        self._programs: list[Process] = []  # the learner's programs (start, start_program)
        self._folders: dict[int, Path] = {}  # a subject's or program's pid -> its own folder
        self._probe: Optional[Publisher] = None
        self.builds: dict[str, Path] = {}
        #: What the learner's code reached for in the subjects (their audit hooks): notes for
        #: the instructor, never a verdict (:mod:`.reaching`).
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
            self._apart(key)
            _ = self.clock  # published before any subject runs: it starts on the judge's time
            where = workspace or self.workspace
            heard = self.observer.counts()
            folder = self._own_folder()
            subject = SubjectProcess(folder, env=subject_env({
                WORKSPACE_ENV: str(where), JUDGE_TOPICS_ENV: json.dumps(sorted(heard[0]))},
                folder), writable=[folder, *self._outboxes])
            self._folders[subject.proc.pid] = folder
            subject.heard_base = heard
            subject.while_waiting = self.observer.floods.raise_any
            self._subjects[key] = subject
            try:
                load(subject)
            except BaseException:
                self._end(key)
                raise
        return subject

    def _own_folder(self) -> Path:
        """A new folder for one subject or program (:func:`.handed.own_folder`)."""
        return handed.own_folder(self._top)

    def _remove_folder(self, pid: int) -> None:
        """The process ``pid`` ended: no later one reads what it wrote.  While grading, its
        sandbox showed it no folder of another process's, and what it wrote stays for the
        grader, who removes the judge's folder; elsewhere its folder is removed now."""
        folder = self._folders.pop(pid, None)
        if folder is not None and self._own_top:
            shutil.rmtree(folder, ignore_errors=True)

    def _apart(self, key: tuple[Any, ...]) -> None:
        """End the subjects that must not run beside the one about to start for ``key``: each
        that holds the course's stand-ins, and every one when the new one will hold them, so
        that no learner's code runs beside the course's version of a part it is graded on."""
        def holds(known: tuple[Any, ...]) -> bool:
            return known[:1] == ('file',) and known[2:3] == ('+',)

        for known in [k for k in self._subjects if k != key and (holds(k) or holds(key))]:
            self._end(known)

    def fresh_folder(self, prefix: str) -> ContextManager[Path]:
        """A new, empty folder of the judge's that the subjects and programs started while it
        is open may write (a bag the learner's function records), removed afterwards with
        all they put there (:func:`.handed.outbox`); read what they left with
        :meth:`taken_back`."""
        return handed.outbox(self.scratch, self._outboxes, prefix)

    def working_pids(self) -> list[int]:
        """The processes of this session's subjects and of the learner's programs it started
        that still run: those whose work every wait of the judge's attends to."""
        for proc in [proc for proc in self._programs if proc.poll() is not None]:
            self._programs.remove(proc)
            self._remove_folder(proc.pid)
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
        self._remove_folder(subject.proc.pid)
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

    def answer_home(self, ref: AnswerRef, workspace: Optional[Path] = None) -> Path:
        """The home folder of the subject that runs ``ref`` (started now if need be)."""
        subject = self.answer_subject(ref, workspace)
        return home_and_tmp(self._folders[subject.proc.pid])[0]

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

    def start(self, argv: list[str], *, cwd: Path, env: Optional[dict[str, str]] = None,
              writable: Sequence[Path] = ()) -> tuple[subprocess.Popen[str], Output]:
        """Start a program of the learner's (sandboxed while grading) in a session of its own,
        with a folder of its own for its home and temporary files.

        :param env: the program's whole environment (default :func:`subject_env`), its home
            and temporary folder moved to its own.  While grading it is set inside the
            sandbox, never on the sandbox's own command: an environment a learner's build
            gave (``PATH``, ``LD_PRELOAD``) must not choose or load the program that sandboxes
            theirs.
        :param writable: folders of the judge's the program is to write (a build's), besides
            its own.
        :return: the process, and its output (stdout and stderr), collected as it comes.
        """
        working.say(f'starting {Path(argv[0]).name}')
        folder = self._own_folder()
        env = handed.at_home(env, folder) if env is not None else subject_env(None, folder)
        prefix = subject_prefix([folder, *self._outboxes, *writable])
        popen_env: Optional[dict[str, str]] = env
        if prefix:
            argv = [sys.executable, '-I', '-c', SET_ENV_AND_EXEC, json.dumps(env), *argv]
            popen_env = None
        try:
            proc = subprocess.Popen([*prefix, *argv], cwd=cwd, env=popen_env, text=True,
                                    stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, start_new_session=True)
        except BaseException:
            shutil.rmtree(folder, ignore_errors=True)
            raise
        self._programs.append(proc)
        self._folders[proc.pid] = folder
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
            return self.start([*python_start(), '-m', 'ros2nb.subject.program', *args],
                              cwd=self.workspace)
        folder = self._own_folder()
        try:
            proc = fork_program(args, str(self.workspace), subject_env(None, folder))
        except BaseException:
            shutil.rmtree(folder, ignore_errors=True)
            raise
        self._programs.append(proc)
        self._folders[proc.pid] = folder
        return proc, Output(proc.stdout)

    def run(self, argv: list[str], *, seconds: float, cwd: Path,
            env: Optional[dict[str, str]] = None, what: Optional[str] = None,
            writable: Sequence[Path] = ()) -> tuple[int, str]:
        """Run a program of the learner's (sandboxed while grading); return code and output.

        :param seconds: what the program gets (:func:`~ros2nb.processes.wait_patiently`):
            seconds of its work while it works, of the wall clock while it waits.
        :param what: the program as its failure names it (default: its file's name).
        :param writable: folders of the judge's it is to write, besides its own (:meth:`start`).
        :raises SubjectHung: when it had them and still runs.
        """
        proc, output = self.start(argv, cwd=cwd, env=env, writable=writable)
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
        for proc in self._programs:
            if proc.poll() is None:
                kill_process_group(proc)
        if hurried:
            shutil.rmtree(self._top if self._own_top else self.scratch, ignore_errors=True)
        if self._observer is not None:
            self._observer.close()
        os.close(self._scratch_fd)
        self._folders.clear()
        shutil.rmtree(self._top if self._own_top else self.scratch, ignore_errors=True)

