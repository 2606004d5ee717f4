"""The ``main()`` checks of notebooks 03 and 04: the file run as a program, then Ctrl+C.

Part of :mod:`ros2nb.checks`.  The judge starts the learner's file as ``ros2 run`` would
(a process of its own, sandboxed while grading), presses Ctrl+C once its node spins, and
reads the exit code and the output; the learner's ``main()`` is read as text (``ast``).
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path
from typing import Optional

from ..errors import CheckFailed
from ..processes import interrupt, kill_process_group
from .base import ARRIVAL_TIMEOUT_S, Judge

#: Seconds a node process gets to exit after Ctrl+C (which comes once its node spins).
EXIT_AFTER_CTRL_C_S = 20.0
#: On Jazzy Ctrl+C shuts rclpy down itself; then, depending on where the signal lands, the spin
#: ends with ExternalShutdownException or a later rclpy.shutdown() fails. One race, one cause:
#: the learner is told the cause, in the same words whichever way the race went.
ALREADY_SHUT_DOWN_MARKS = ('ExternalShutdownException', 'rcl_shutdown already called')


def _function(tree: ast.Module, name: str) -> Optional[ast.FunctionDef]:
    return next((s for s in tree.body if isinstance(s, ast.FunctionDef) and s.name == name), None)


def _calls(nodes: list[ast.stmt]) -> set[str]:
    names = set()
    for statement in nodes:
        for node in ast.walk(statement):
            if isinstance(node, ast.Call):
                func = node.func
                names.add(func.attr if isinstance(func, ast.Attribute) else
                          func.id if isinstance(func, ast.Name) else '')
    return names


def _cleanup_verdict(main: ast.FunctionDef) -> None:
    """main() must destroy its node and shut rclpy down, in a ``finally:`` block."""
    in_finally = _calls([s for node in ast.walk(main) if isinstance(node, ast.Try)
                         for s in node.finalbody])
    anywhere = _calls(main.body)
    if 'destroy_node' not in anywhere:
        raise CheckFailed('main() never destroys its node: call node.destroy_node() when the '
                          'spin ends (the tutorial\'s subscriber forgot it).')
    if not anywhere & {'try_shutdown', 'shutdown'}:
        raise CheckFailed('main() never shuts rclpy down: call rclpy.try_shutdown() when the '
                          'spin ends.')
    if 'destroy_node' not in in_finally or not in_finally & {'try_shutdown', 'shutdown'}:
        raise CheckFailed('main() cleans up only when the spin ends normally: destroy the node '
                          'and call rclpy.try_shutdown() in a finally: block.')


def run_main(judge: Judge, relative: str, node_name: str, part: int = 5) -> str:
    """Run the learner's file, press Ctrl+C once its node spins; the verdict, or the sentence."""
    path = judge.workspace / relative
    if not path.is_file():
        raise CheckFailed(f'{path.name} does not exist yet: run the %%part cells that write it.')
    try:
        tree = ast.parse(path.read_text())
    except SyntaxError as error:
        raise CheckFailed(f'{path.name} line {error.lineno}: SyntaxError: {error.msg}.') from None
    main = _function(tree, 'main')
    if main is None:
        raise CheckFailed(f'{path.name} has no main() function yet: write part {part}.')
    observer = judge.observer
    judge.drop(('file', relative))  # the node runs alone, as in a terminal: one of its name
    proc, output = judge.start([sys.executable, str(path)], cwd=judge.workspace)
    # Ctrl+C once the node spins (it answers a parameter call), as a learner presses it
    # once the node runs: earlier, a busy machine would decide what the learner is told.
    # The graph is read once for the verdict: the read that ended the wait, not a second one.
    started = observer.wait_until(
        lambda: proc.poll() is not None or observer.has_node(node_name), ARRIVAL_TIMEOUT_S,
    ) and proc.poll() is None
    spinning = started and observer.spins(node_name)
    if proc.poll() is not None:
        raise _ended_early(path, part, output.text(), proc.returncode)
    if not started:  # the judge's own graph: no node of that name appeared while it ran
        kill_process_group(proc)
        raise CheckFailed(f'{path.name} never started its node {node_name} (none appeared in the '
                          f'grader\'s ROS graph within {ARRIVAL_TIMEOUT_S:g} s): main() should bring rclpy up, '
                          'create the node and spin it until Ctrl+C.')
    interrupt(proc)
    try:
        code = proc.wait(EXIT_AFTER_CTRL_C_S)
    except subprocess.TimeoutExpired:
        kill_process_group(proc)
        raise CheckFailed(f'{path.name} did not stop within {EXIT_AFTER_CTRL_C_S:g} s of Ctrl+C: '
                          'let KeyboardInterrupt end the spin.') from None
    text = output.text()
    stuck = _last_frame(text, path)
    if not spinning and stuck is not None and stuck[1] != 'main':
        raise CheckFailed(f'{path.name} never reached its spin: line {stuck[0]} in {stuck[1]} '
                          f'({stuck[2]}) was still running at Ctrl+C; no loop in a constructor or '
                          'callback: repeat work with a timer (create_timer) and let main() spin.')
    if not spinning:  # the node was there but never answered: main() did not spin it
        raise CheckFailed(f'{path.name} created its node {node_name} but never spun it (it did '
                          'not answer the grader): main() should spin it with rclpy.spin(node) '
                          'until Ctrl+C.')
    if code != 0 or 'Traceback' in text:
        last = _error_line(text)
        already = any(mark in last for mark in ALREADY_SHUT_DOWN_MARKS)
        what = 'Ctrl+C had already shut rclpy down' if already else last
        raise CheckFailed(f'{path.name} exited with code {code} after Ctrl+C ({what}): '
                          f'{_ctrl_c_advice(main, already)}.')
    _cleanup_verdict(main)
    return (f'{path.name} stops cleanly on Ctrl+C (exit code 0, no traceback) and cleans up in '
            'finally.')


def _ended_early(path: Path, part: int, text: str, code: int) -> CheckFailed:
    """Why the learner's program ended before Ctrl+C, from its output, as the check's line."""
    if 'NotImplementedError' in text:
        return CheckFailed(f'main() still raises NotImplementedError: write part {part} where '
                           'it says YOUR CODE HERE.')
    if 'Traceback' in text:
        return CheckFailed(f'{path.name} crashed before Ctrl+C{_crash_place(text, path)} '
                           f'({_error_line(text)}): fix that line, then run this check again.')
    return CheckFailed(f'{path.name} ended by itself before Ctrl+C (exit code {code}); main() '
                       'should spin until Ctrl+C.')


def _caught(main: ast.FunctionDef) -> set[str]:
    """The exception names ``main()``'s ``except`` clauses catch."""
    names: set[str] = set()
    for node in ast.walk(main):
        if isinstance(node, ast.ExceptHandler) and node.type is not None:
            for part in ast.walk(node.type):
                if isinstance(part, (ast.Name, ast.Attribute)):
                    names.add(part.id if isinstance(part, ast.Name) else part.attr)
    return names


def _ctrl_c_advice(main: ast.FunctionDef, already_shut_down: bool) -> str:
    """What to change in main(), from whether Ctrl+C had shut rclpy down and what it catches."""
    caught = _caught(main)
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


def _last_frame(text: str, path) -> Optional[tuple[int, str, str]]:
    """(line, function, source) of the learner's file's last frame in a traceback, or None."""
    frames = re.findall(rf'File "{re.escape(str(path))}", line (\d+), in (\w+)', text)
    if not frames:
        return None
    number, function = int(frames[-1][0]), frames[-1][1]
    lines = path.read_text().splitlines()
    return number, function, lines[number - 1].strip() if 0 < number <= len(lines) else ''


def _crash_place(text: str, path) -> str:
    """`` at line N (source)`` for the learner's file's last frame in a traceback, or ''."""
    frame = _last_frame(text, path)
    return '' if frame is None else f' at line {frame[0]} ({frame[2]})'


def last_line(text: str) -> str:
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return lines[-1][:200] if lines else 'no output'
