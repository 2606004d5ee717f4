"""What a mutant's answer is worth to the learner: killed well, survived, or bad.

:func:`verdict` reads one run mutant (``mutation_runs.Outcome`` as a dict) and judges both
paths, the lab's check and the grader's, by the course's promise (GUIDE.md): the check
fails with one line (at most three with context) that names the learner's own line or its
effect and what to do.

- **killed well**: both paths fail so;
- **survived**: both pass: the mutant is equivalent (:data:`EQUIVALENT` says why) or the
  check is too weak;
- **bad**: a traceback through rclpy, pybind or ros2nb; a line pointing at code the mutant
  did not change (nor uses a name it changed); more than three lines; no answer (the cell
  ran past its patience); the lab and the grader disagreeing (one passes, one fails).

A line "points at" code when it quotes it: ``(FILE line N: CODE)``, ``cell line N: CODE``,
``at line N (CODE)``, or a traceback's ``File ..., line N`` with its code under it.
"""

from __future__ import annotations

import re
from typing import Optional

_KEPT_BY_THE_NODE = ("rclpy's node keeps every {0} it made (node.{0}s), whatever self keeps: "
                     'it works the same, under any name or none')
_STOPPED_ALREADY = ('on Jazzy Ctrl+C and a shutdown from outside have already shut rclpy down '
                    "when the spin ends, and the process's exit destroys the node: nothing "
                    'that the grader, or anyone, can observe differs')
_DEVELOP = ('[develop] is read only by a development install (setup.py develop); colcon, as '
            'the course runs it, makes a normal install, which [install] alone decides')
#: Survivors that are no mistake at all: a part of their mutant's name (``operator | what``)
#: and why no behaviour differs.
EQUIVALENT: dict[str, str] = {
    'constant changed | QUEUE_DEPTH -> 5': (
        'a queue of 5 keeps what a queue of 10 keeps here: at one reading a second nothing '
        'waits in it (the depth matters only to a subscription that falls behind)'),
    'local, not attribute | self.timer = -> timer =': _KEPT_BY_THE_NODE.format('timer'),
    'local, not attribute | self.subscription = -> subscription =':
        _KEPT_BY_THE_NODE.format('subscription'),
    'name one edit away | .subscription -> .subsciption':
        _KEPT_BY_THE_NODE.format('subscription'),
    "tutorial mistake | the tutorial's literals for the constants (equivalent)": (
        "the same values, written as the tutorial writes them: honest code in its style"),
    "tutorial mistake | the tutorial's callback with 18.0 for its floor (equivalent)": (
        'the step added, then clamped into [18.0, 28.0] in a second statement: the same walk'),
    "tutorial mistake | the tutorial's callback: 'Status:{status}' without a space": (
        "the line still shows the reading with two decimals and its status: the task's line is "
        'an example, the check reads what it must hold'),
    'arguments swapped | random.uniform(-MAX_STEP_C <-> MAX_STEP_C)': (
        'uniform(b, a) draws from the same interval as uniform(a, b)'),
    'arguments swapped | max(MIN_TEMPERATURE_C <-> min(': 'max does not depend on the order',
    'arguments swapped | min(MAX_TEMPERATURE_C <-> self.temperature + step)':
        'min does not depend on the order',
    'statement deleted | node.destroy_node()': _STOPPED_ALREADY,
    'statement deleted | rclpy.try_shutdown()': _STOPPED_ALREADY,
    "arguments swapped | ros2nb.bag_record('/temperature' <-> '/rosout')": (
        'the bag records the same two topics, in whichever order they are named'),
    '05-setup-cfg | name one edit away | [develop] -> [devlop]': _DEVELOP,
    '05-setup-cfg | name one edit away | script_dir -> scrit_dir': _DEVELOP,
    '05-setup-cfg | name one edit away | $base/lib/sensor_simulator -> .../sensor_imulator':
        _DEVELOP,
    '05-setup-cfg | constant changed | script_dir: $base/lib -> $base/bin': _DEVELOP,
    '05-setup-cfg | statement deleted | [develop] and its line': _DEVELOP,
    '05-setup-cfg | statement deleted | script_dir=$base/lib/sensor_simulator': _DEVELOP,
    '05-setup-cfg | tutorial mistake | install_scripts with dashes': (
        'the package built from it runs with ros2 run, and its build warns of nothing (as it '
        'does for script-dir, which the check names): nothing the grader can observe differs'),
    '02-create-a-package-challenge-1 | import removed | from pathlib import Path': (
        'the notebook imports Path in its first cell, and the grader runs that cell too'),
    '06-fan-controller | message for its value | command.data -> command': (
        "only the log line changes (a message is always true, so it says 'Fan on'): the task "
        'makes that line optional and grades the commands on /fan_command, which are the same'),
    '01-create-a-workspace-challenge-1 | import removed | from pathlib import Path': (
        'the notebook imports Path before (its cell with the tutorial\'s two paths), and the '
        'grader runs that cell too'),
}

#: Words in a line that only a traceback through ros2nb or the ROS libraries shows.
THROUGH_LIBRARIES = ('site-packages', '/ros2nb/', 'rclpy/', '_rclpy', 'pybind11',
                     'incompatible function arguments', 'The grader could not finish')
MOST_LINES = 3

_QUOTED = (re.compile(r'(?:^|\()\s*(?P<file>[\w.<> -]+?) line (?P<line>\d+): (?P<code>.+?)\)?$'),
           re.compile(r'at line (?P<line>\d+) \((?P<code>.+?)\)'))
_FRAME = re.compile(r'^\s*File "(?P<file>[^"]+)", line (?P<line>\d+)')


def quoted_lines(lines: list[str]) -> list[tuple[str, str]]:
    """``(place, code)`` for every line of the learner's code the answer quotes."""
    found = []
    for index, line in enumerate(lines):
        frame = _FRAME.match(line)
        if frame:
            code = lines[index + 1].strip() if index + 1 < len(lines) else ''
            if code and not _FRAME.match(lines[index + 1]) and ':' not in code[:0]:
                found.append((f'{frame["file"]} line {frame["line"]}', code))
            else:
                found.append((f'{frame["file"]} line {frame["line"]}', ''))
            continue
        for pattern in _QUOTED:
            for match in pattern.finditer(line):
                found.append((f'{match.groupdict().get("file") or ""} line {match["line"]}',
                              match['code'].strip()))
    return found


def _words(text: str) -> set[str]:
    return set(re.findall(r'\w+', text))


def _blame(outcome: dict, code: str, said: str) -> Optional[str]:
    """Why quoting ``code`` blames a line the mutant left alone, or None when it is the
    mutant's own line, or shows its effect: the line uses a name the mutant changed, or the
    answer (``said``) names one (what a deleted line should have done, say)."""
    if not code:
        return 'it names a line without showing its code'
    lines = outcome['source'].split('\n')
    stripped = [line.strip() for line in lines]
    affected = set(outcome['affected'])
    at = [i for i, line in enumerate(stripped) if line and (line == code or
                                                             code.startswith(line))]
    if any(i in outcome['changed'] for i in at):
        return None
    if affected & (_words(code) | _words(said)):
        return None
    if at:
        return f'it points at line {at[0] + 1} of the cell, which the mutant did not change'
    return 'it points at code the learner did not write or did not change'


def path_verdict(outcome: dict, shown: dict) -> tuple[str, list[str]]:
    """``('passed' | 'failed well' | 'bad', reasons)`` for one path's answer."""
    if shown['hung']:
        return 'bad', ['no answer: the check ran past its patience']
    if not shown['error']:
        return 'passed', []
    reasons = []
    lines = [line for line in shown['error'] if line.strip()]
    if len(lines) > MOST_LINES:
        reasons.append(f'{len(lines)} lines')
    through = [word for word in THROUGH_LIBRARIES if any(word in line for line in lines)]
    if through:
        reasons.append(f'shows {through[0]!r}')
    for place, code in quoted_lines(lines):
        why = _blame(outcome, code, '\n'.join(lines))
        if why:
            reasons.append(f'{place}: {why}')
    return ('bad' if reasons else 'failed well'), reasons


def verdict(outcome: dict) -> tuple[str, list[str]]:
    """``(verdict, reasons)``: ``'killed well'``, ``'survived (equivalent)'``,
    ``'survived (weak)'`` or ``'bad'``; for the unchanged answer ``'passes'`` or ``'bad'``."""
    lab, lab_why = path_verdict(outcome, outcome['lab'])
    grading, grading_why = path_verdict(outcome, outcome['grading'])
    cell, cell_why = path_verdict(outcome, outcome['cell'])
    reasons = [f'lab: {r}' for r in lab_why] + [f'grading: {r}' for r in grading_why]
    reasons += [f'the cell itself: {r}' for r in cell_why]
    if outcome['operator'] == 'none':
        if lab == grading == 'passed':
            return 'passes', []
        return 'bad', reasons or ['the course\'s own answer fails its check']
    if reasons:
        return 'bad', reasons
    if (lab == 'passed') != (grading == 'passed'):
        passing = 'the lab' if lab == 'passed' else 'the grader'
        return 'bad', [f'only {passing} passes it']
    if lab == 'passed':
        reason = equivalent(outcome['ident'])
        return ('survived (equivalent)', [reason]) if reason else ('survived (weak)', [])
    return 'killed well', []


def equivalent(ident: str) -> Optional[str]:
    """Why the mutant named ``ident`` is no mistake, if :data:`EQUIVALENT` says."""
    return next((why for part, why in EQUIVALENT.items() if part in ident), None)
