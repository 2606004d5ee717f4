"""The ``main()`` checks of notebooks 03, 04 and 06: ``main()`` run as a program, then stopped.

Part of :mod:`ros2nb.checks`.  The judge starts the learner's ``main()`` as ``ros2 run``
would (:mod:`ros2nb.subject.program`, a process of its own, sandboxed while grading), presses
Ctrl+C once its node spins (it answers the judge's own call), and reads the exit code and
the output; then again with a shutdown from outside (SIGTERM).  When the node class is
at fault, the course's stand-in node takes its place and ``main()`` runs again, so that
``main()`` is graded on its own.  The learner's ``main()`` read as text only picks the
advice of a failure the judge has seen.
"""

from __future__ import annotations

import ast
import re
import signal
import subprocess
from pathlib import Path
from typing import Optional

from .. import working
from ..errors import CheckFailed
from ..explain.programs import read_explained
from ..processes import Process, interrupt, kill_process_group, until_waiting, wait_patiently
from ..judge_interface import Judge, Observer, ProgramOutput
from .source import TEXT

#: Seconds a node process gets to exit after Ctrl+C (which comes once its node spins).
EXIT_AFTER_CTRL_C_S = 20.0
#: Seconds a program gets to put its node in the graph: of its own work while it works (a
#: busy machine makes it slow, not wrong), of the wall clock while it waits for nothing (an
#: honest main() puts its node there within a second or two of work; at 30 s a main() that
#: never starts ROS kept the learner waiting a minute, its own run and the stand-in's).
START_PATIENCE_S = 10.0
#: Seconds between two looks at how much the program has worked.
LOOK_AGAIN_S = 0.5
#: Seconds a program has to end after a shutdown from outside before the judge calls its node
#: once.  rclpy (Jazzy) handles SIGTERM in a thread of its own: it wakes the spin, then shuts
#: the context down.  A spin that woke and looked in between (a busy machine) waits on with a
#: context already shut down, until something arrives: a node that only subscribes hung there
#: (seen once in make test beside two CPU burners).  The call is that something; it ends
#: nothing that a shutdown from outside would not end.
WAKE_AFTER_S = 2.0
#: How a running node is stopped, in turn: Ctrl+C in its terminal, and a shutdown from
#: outside (SIGTERM, as ``ros2 launch`` after its grace period, systemd or docker stop send).
#: On Jazzy the first ends the spin with KeyboardInterrupt, the second with
#: ExternalShutdownException, every time.
STOPPING_SIGNALS = {signal.SIGINT: 'Ctrl+C',
                    signal.SIGTERM: 'a shutdown from outside (SIGTERM)'}
STOP_EXCEPTIONS = {signal.SIGINT: 'KeyboardInterrupt',
                   signal.SIGTERM: 'ExternalShutdownException'}
#: What a stop itself raises in a main(): its line is the stop's, not an error of the code's.
STOP_KINDS = ('KeyboardInterrupt', 'ExternalShutdownException', 'RCLError')
#: On Jazzy Ctrl+C shuts rclpy down itself; then, depending on where the signal lands, the spin
#: ends with ExternalShutdownException or a later rclpy.shutdown() fails. One race, one cause:
#: the learner is told the cause, in the same words whichever way the race went.
ALREADY_SHUT_DOWN_MARKS = ('ExternalShutdownException', 'rcl_shutdown already called')
#: rclpy's own race at a shutdown from outside: its signal thread wakes the spin before it
#: shuts the context down, and a spin that looks in between makes its next wait set on a
#: context that is gone (RCLError), whatever main() catches; a busy machine makes it likelier
#: (docs/decisions.md).  The run is made again: what main() does counts, not the race.
RACE_MARKS = ('failed to initialize wait set', 'context is not valid')
#: Runs of main() a shutdown gets at most while rclpy's race decides how it ends.
RACE_RUNS = 3
#: Runs of main() that must stop cleanly, per signal.  The same race lets a main() that
#: catches only KeyboardInterrupt end cleanly, now and then, after a shutdown from outside
#: (its spin returns as if nothing happened): one clean run says little, three in a row do.
CLEAN_STOPS = {signal.SIGINT: 1, signal.SIGTERM: 3}


def _function(tree: ast.Module, name: str) -> Optional[ast.FunctionDef]:
    return next((s for s in tree.body if isinstance(s, ast.FunctionDef) and s.name == name), None)


def run_main(judge: Judge, relative: str, node_name: str, part: int = 5,
             node_class: Optional[str] = None) -> str:
    """Run the learner's ``main()``, press Ctrl+C once its node spins; the verdict, or the
    sentence.  With ``node_class``, a failure is tried again with the course's stand-in for
    that class: when ``main()`` then stops cleanly, the class was at fault, not ``main()``."""
    path = judge.workspace / relative
    if not path.is_file():
        raise CheckFailed(f'{path.name} does not exist yet: run the %%part cells that write it.')
    judge.drop(('file', relative))  # the node runs alone, as in a terminal: one of its name
    for sig in STOPPING_SIGNALS:
        try:
            _stop_run(judge, path, node_name, part, sig)
        except CheckFailed:
            if node_class is None:
                raise
            _stop_run(judge, path, node_name, part, sig, stand_in=node_class)  # main() alone
    return (f'main() starts {node_name}, spins it, and stops cleanly on Ctrl+C and on a '
            'shutdown from outside (exit code 0, no traceback).')


def _stop_run(judge: Judge, path: Path, node_name: str, part: int, sig: signal.Signals,
              stand_in: Optional[str] = None) -> None:
    """Runs of ``main()`` stopped with ``sig`` (its node class replaced by the stand-in when
    given): :data:`CLEAN_STOPS` of them must end cleanly; a run that rclpy's own shutdown race
    ended is run again, :data:`RACE_RUNS` times at most."""
    clean = races = 0
    while clean < CLEAN_STOPS[sig]:
        proc, output = judge.start_program(path, stand_in)
        try:
            _watch_stop(judge.observer, path, node_name, part, proc, output, sig)
            clean += 1
        except _ShutdownRace:
            races += 1
            if races == RACE_RUNS:
                raise
        finally:
            kill_process_group(proc)
            judge.observer.floods.ended()  # its late lines never count in the next run


class _ShutdownRace(CheckFailed):
    """``main()`` ended on rclpy's own race between its wake-up and its shutdown
    (:data:`RACE_MARKS`), not on what the learner wrote."""


def _watch_stop(observer: Observer, path: Path, node_name: str, part: int, proc: Process,
                output: ProgramOutput, sig: signal.Signals) -> None:
    """Raise for what the running ``main()`` did wrong, as the judge sees it from outside."""
    # Ctrl+C once the node spins (it answers a parameter call), as a learner presses it
    # once the node runs: earlier, a busy machine would decide what the learner is told.
    # The graph is read once for the verdict: the read that ended the wait, not a second one.
    started = _wait_for_node(observer, proc, node_name) and proc.poll() is None
    spinning = started and observer.spins(node_name)
    ended = proc.poll()
    if ended is not None:
        raise _ended_early(path, part, output.text(), ended)
    if not started:  # the judge's own graph: no node of that name appeared while it ran
        raise CheckFailed(f'{path.name} never started its node {node_name} (none appeared in the '
                          f'grader\'s ROS graph while the program had {START_PATIENCE_S:g} s to '
                          'start it): main() should bring rclpy up, create the node and spin it '
                          'until Ctrl+C.')
    until_waiting(proc, START_PATIENCE_S)  # the node idle in its spin, its call answered
    pressed = STOPPING_SIGNALS[sig]
    working.say(f'{pressed} for {node_name}')
    interrupt(proc, sig)
    code = _wait_for_exit(observer, proc, node_name, sig)
    if code is None:
        raise CheckFailed(f'{path.name} did not stop within {EXIT_AFTER_CTRL_C_S:g} s of '
                          f'{pressed}: let {STOP_EXCEPTIONS[sig]} end the spin.')
    text = output.text()
    stuck = _last_frame(text, path)
    if not spinning and stuck is not None and stuck[1] != 'main':
        raise CheckFailed(f'{path.name} never reached its spin: line {stuck[0]} in {stuck[1]} '
                          f'({stuck[2]}) was still running at {pressed}; no loop in a '
                          'constructor or callback: repeat work with a timer (create_timer) '
                          'and let main() spin.')
    if not spinning:  # the node was there but never answered: main() did not spin it
        raise _crashed(path, text) or CheckFailed(_NOT_SPUN.format(file=path.name))
    if code != 0 or 'Traceback' in text:
        facts = read_explained(text)  # an error of the learner's code, not of the stop
        if facts and facts.get('explanation') and facts.get('type') not in STOP_KINDS:
            where = f' ({facts["where"]})' if facts.get('where') else ''
            raise CheckFailed(f'{path.name} exited with code {code} after {pressed}: '
                              f'{facts["explanation"]}{where}')
        last = _error_line(text)
        if all(mark in last for mark in RACE_MARKS):
            raise _ShutdownRace(f'{path.name} exited with code {code} after {pressed}: rclpy '
                                f'ended its spin on its own shutdown race ({last}).')
        # Ctrl+C shuts rclpy down before the spin ends (the race ALREADY_SHUT_DOWN_MARKS
        # names); a shutdown from outside ends the spin with ExternalShutdownException itself.
        already = any(mark in last for mark in ALREADY_SHUT_DOWN_MARKS) and (
            sig == signal.SIGINT or 'rcl_shutdown already called' in last)
        what = f'{pressed} had already shut rclpy down' if already else last
        raise CheckFailed(f'{path.name} exited with code {code} after {pressed} ({what}): '
                          f'{_ctrl_c_advice(path, already)}.')


def _wait_for_exit(observer: Observer, proc: Process, node_name: str, sig: signal.Signals
                   ) -> Optional[int]:
    """The program's exit code once it ended after ``sig``, or None when it had
    :data:`EXIT_AFTER_CTRL_C_S` (of its work) and still runs; after a shutdown from outside,
    its node is called once if it still runs after :data:`WAKE_AFTER_S`."""
    if sig == signal.SIGTERM:
        try:
            return proc.wait(WAKE_AFTER_S)
        except subprocess.TimeoutExpired:
            observer.spins(node_name, seconds=WAKE_AFTER_S)  # its answer does not matter
    return wait_patiently(proc, EXIT_AFTER_CTRL_C_S)


def _wait_for_node(observer: Observer, proc: Process, node_name: str) -> bool:
    """Wait until the node is in the judge's graph or the program ended: True then, False
    once the program had :data:`START_PATIENCE_S` (the judge's waits attend to its work)."""
    return observer.wait_until(lambda: proc.poll() is not None or observer.has_node(node_name),
                               START_PATIENCE_S)


def _ended_early(path: Path, part: int, text: str, code: int) -> CheckFailed:
    """Why the learner's program ended before Ctrl+C, from its output, as the check's line."""
    if 'has no main() function' in text:  # ros2nb.subject.program found none to call
        return CheckFailed(f'{path.name} has no main() function yet: write part {part}.')
    if 'NotImplementedError' in text:
        return CheckFailed(f'main() still raises NotImplementedError: write part {part} where '
                           'it says YOUR CODE HERE.')
    crashed = _crashed(path, text)
    if crashed is not None:
        return crashed
    if 'Traceback' in text:
        return CheckFailed(f'{path.name} crashed before Ctrl+C{_crash_place(text, path)} '
                           f'({_error_line(text)}): fix that line, then run this check again.')
    if code == 0:  # as when its node was seen, not spinning: how busy the machine is decides
        return CheckFailed(_NOT_SPUN.format(file=path.name))
    return CheckFailed(f'{path.name} ended by itself before Ctrl+C (exit code {code}); main() '
                       'should spin until Ctrl+C.')


#: A main() that never spins, whether the judge saw its node before it ended or not.
_NOT_SPUN = ('{file} did not spin its node until Ctrl+C (it ended by itself, or did not answer '
             'the grader): main() should spin it with rclpy.spin(node) until Ctrl+C.')


def _crashed(path: Path, text: str) -> Optional[CheckFailed]:
    """The line for an error of the learner's code that ended the program by itself (its
    explained line, :mod:`ros2nb.explain.programs`), or None: whether the judge pressed
    Ctrl+C before it was reaped or not, as a busy machine decides."""
    facts = read_explained(text)
    if facts is None or not facts.get('explanation') or facts.get('type') in STOP_KINDS:
        return None
    where = f' ({facts["where"]})' if facts.get('where') else ''
    return CheckFailed(f'{path.name} crashed before Ctrl+C: {facts["explanation"]}{where}')


def _caught(main: ast.FunctionDef) -> set[str]:
    """The exception names ``main()``'s ``except`` clauses catch."""
    names: set[str] = set()
    for node in ast.walk(main):
        if isinstance(node, ast.ExceptHandler) and node.type is not None:
            for part in ast.walk(node.type):
                if isinstance(part, (ast.Name, ast.Attribute)):
                    names.add(part.id if isinstance(part, ast.Name) else part.attr)
    return names


def _ctrl_c_advice(path: Path, already_shut_down: bool) -> str:
    """What to change in main(), from whether Ctrl+C had shut rclpy down and what main()
    catches (its text, read only to word the advice)."""
    text = TEXT.read(path)
    try:
        main = _function(ast.parse(text), 'main') if text is not None else None
    except (SyntaxError, ValueError):
        main = None
    caught = _caught(main) if main is not None else set()
    if already_shut_down and {'KeyboardInterrupt', 'ExternalShutdownException'} <= caught:
        return ('shut down with rclpy.try_shutdown() instead of rclpy.shutdown(): on Jazzy '
                'Ctrl+C has already shut rclpy down')
    missing = [name for name in ('KeyboardInterrupt', 'ExternalShutdownException')
               if name not in caught]
    if missing:
        return (f'catch {" and ".join(missing)} around the spin (both end it on Jazzy), and shut '
                'down with rclpy.try_shutdown()')
    return 'clean up in a finally: block with node.destroy_node() and rclpy.try_shutdown()'


def _error_line(text: str) -> str:
    """The last line of a traceback, without module paths or rcl's C source location."""
    line = last_line(text)
    line = re.sub(r'^(?:[A-Za-z_][\w]*\.)+(?=\w+(?:Error|Exception)\b)', '', line)
    return re.sub(r', at /\S+:\d+$', '', line)


def _last_frame(text: str, path: Path) -> Optional[tuple[int, str, str]]:
    """(line, function, source) of the learner's file's last frame in a traceback, or None."""
    frames = re.findall(rf'File "{re.escape(str(path))}", line (\d+), in (\w+)', text)
    if not frames:
        return None
    number, function = int(frames[-1][0]), frames[-1][1]
    lines = (TEXT.read(path) or '').splitlines()
    return number, function, lines[number - 1].strip() if 0 < number <= len(lines) else ''


def _crash_place(text: str, path: Path) -> str:
    """`` at line N (source)`` for the learner's file's last frame in a traceback, or ''."""
    frame = _last_frame(text, path)
    return '' if frame is None else f' at line {frame[0]} ({frame[2]})'


def last_line(text: str) -> str:
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return lines[-1][:200] if lines else 'no output'
