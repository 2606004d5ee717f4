"""What a mutant's answer is worth to the learner: killed well, survived, or bad.

:func:`verdict` reads one run mutant (``mutation_runs.Outcome`` as a dict) and judges both
paths, the lab's check and the grader's, by the course's promise (GUIDE.md): the check
fails with one line (at most three with context) that names the learner's own line or its
effect and what to do.

- **killed well**: both paths fail so;
- **survived**: both pass: the mutant is equivalent (an excuse of :data:`EXCUSES` says why)
  or the check is too weak;
- **bad**: a traceback through rclpy, pybind or ros2nb; a line pointing at code the mutant
  did not change (nor uses a name it changed); more than three lines; no answer (the cell
  ran past its patience); the lab and the grader disagreeing (one passes, one fails).

A line "points at" code when it quotes it: ``(FILE line N: CODE)``, ``cell line N: CODE``,
``at line N (CODE)``, or a traceback's ``File ..., line N`` with its code under it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from typing import Optional

from mutation_cells import answers, notebook

#: Runs of the answer as written that both paths must pass.
PASSING_RUNS = ('cell run twice', 'run again after a failed check')

@dataclass(frozen=True)
class Excuse:
    """Mutants that are no mistake: the parts of their names (``answer | operator | what``)
    it covers, why each behaves as the answer does, and one of them, its witness, which
    ``tests/test_mutants.py`` runs to see that it still does (it must survive both paths).
    """

    covers: tuple[str, ...]
    why: str
    witness: str


#: Every excuse, at most :data:`MOST_EXCUSES`: a survivor none covers is a weak check.
EXCUSES: tuple[Excuse, ...] = (
    Excuse(("tutorial mistake | the tutorial's literals for the constants (equivalent)",
            "tutorial mistake | the tutorial's callback with 18.0 for its floor (equivalent)",
            "tutorial mistake | the tutorial's callback: 'Status:{status}' without a space"),
           "the tutorial's own code where it is right, honest code in its style: the constants' "
           'values written out, the floor of 18.0 clamped in a second statement, a status line '
           "with 'Status:' and no space (the check reads what a line must hold: the reading "
           'with two decimals and its status)',
           "04-monitor-callback | tutorial mistake | the tutorial's callback: 'Status:{status}' "
           'without a space'),
    Excuse(('arguments swapped | random.uniform(-MAX_STEP_C <-> MAX_STEP_C)',
            'arguments swapped | max(MIN_TEMPERATURE_C <-> min(',
            'arguments swapped | min(MAX_TEMPERATURE_C <-> self.temperature + step)'),
           'uniform(b, a) draws from the same interval as uniform(a, b), and neither max nor '
           'min depends on the order of its arguments',
           '03-sensor-callback | arguments swapped | random.uniform(-MAX_STEP_C <-> MAX_STEP_C) '
           '(line 7)'),
    Excuse(("arguments swapped | ros2nb.bag_record('/temperature' <-> '/rosout')",),
           'the bag records the same two topics, in whichever order they are named',
           "10-record-hour | arguments swapped | ros2nb.bag_record('/temperature' <-> "
           "'/rosout') (line 6)"),
    Excuse(('01-create-a-workspace-challenge-1 | import removed | from pathlib import Path',
            '02-create-a-package-challenge-1 | import removed | from pathlib import Path'),
           'the notebook imports Path in a cell before the answer, and the grader runs that '
           'cell too',
           '02-create-a-package-challenge-1 | import removed | from pathlib import Path (line 2)'),
    Excuse(('05-setup-cfg | tutorial mistake | install_scripts with dashes',),
           'the package built from it runs with ros2 run, and its build warns of nothing (as it '
           'does for script-dir, which the check names): nothing the grader can observe differs',
           '05-setup-cfg | tutorial mistake | install_scripts with dashes (the older template)'),
    Excuse(('05-setup-cfg | name one edit away | [develop] -> [devlop]',
            '05-setup-cfg | name one edit away | script_dir -> scrit_dir',
            '05-setup-cfg | statement deleted | [develop] and its line',
            '05-setup-cfg | statement deleted | script_dir=$base/lib/sensor_simulator'),
           "without [develop]'s script_dir, setuptools' development install (colcon build "
           "--symlink-install) takes [install]'s install_scripts: both builds put the "
           'executables where ros2 run looks, as the notebook says',
           '05-setup-cfg | statement deleted | [develop] and its line'),
    Excuse(('local, not attribute | self.timer = -> timer =',
            'local, not attribute | self.subscription = -> subscription =',
            'name one edit away | .subscription -> .subsciption',
            'name one edit away | .timer -> .timr'),
           "rclpy's node keeps every timer and subscription it made (node.timers, "
           'node.subscriptions), whatever self keeps: it works the same under any name or none, '
           'as the notebooks say',
           '04-monitor-constructor | local, not attribute | self.subscription = -> subscription '
           '= (line 11)'),
    Excuse(('keyword left out | rclpy.init: args= left out',),
           'ros2 run calls main() with no arguments, so args is None, which rclpy.init takes '
           'when no args= is given',
           '03-sensor-main | keyword left out | rclpy.init: args= left out (line 8)'),
    Excuse(('statement deleted | node.destroy_node()', 'statement deleted | rclpy.try_shutdown()',
            'parentheses left out | node.destroy_node() -> node.destroy_node',
            'parentheses left out | rclpy.try_shutdown() -> rclpy.try_shutdown'),
           'on Jazzy Ctrl+C and a shutdown from outside have already shut rclpy down when the '
           "spin ends, and the process's exit destroys the node: nothing that the grader, or "
           'anyone, can observe differs',
           '03-sensor-main | statement deleted | node.destroy_node() (line 15)'),
    Excuse(("wrong value type | PUBLISH_PERIOD_S -> '1.0'",),
           "rclpy's create_timer reads its period with float(): '1.0' is a period of 1.0 s",
           "03-sensor-constructor | wrong value type | PUBLISH_PERIOD_S -> '1.0' (line 13)"),
    Excuse(('09-qos-newest-only | keyword left out | QoSProfile: history= left out',
            '09-qos-latched-thresholds | keyword left out | QoSProfile: reliability= left out'),
           "a QoSProfile's history is KEEP_LAST and its reliability RELIABLE unless told "
           'otherwise: without the keyword it is the same profile, and rclpy says so '
           '(QoSProfile(depth=1) == QoSProfile(history=KEEP_LAST, depth=1))',
           '09-qos-newest-only | keyword left out | QoSProfile: history= left out (line 3)'),
    Excuse(('10-record-hour | keyword left out | ros2nb.spin: show_logs= left out',),
           "show_logs=False only keeps the kernel from printing the hour's 7200 log lines: "
           'what the nodes publish and log, and the bag, are the same',
           '10-record-hour | keyword left out | ros2nb.spin: show_logs= left out (line 7)'),
    Excuse(('constant changed | QUEUE_DEPTH -> 5',),
           'a queue of 5 keeps what a queue of 10 keeps here: at one reading a second nothing '
           'waits in it (the depth matters only to a subscription that falls behind)',
           '03-sensor-constructor | constant changed | QUEUE_DEPTH -> 5 (line 12)'),
    Excuse(('06-fan-controller | statement deleted | self.get_logger().info(f"Fan',),
           "the task makes the fan's log line per command optional (the check does not need "
           'it), and grades the commands on /fan_command, which are the same',
           '06-fan-controller | statement deleted | self.get_logger().info(f"Fan {(\'on\' if '
           "command.data else 'of (line 21)"),
)
#: Most excuses (issue 76): each must earn its place.
MOST_EXCUSES = 15
#: Each covered part, and its excuse.
EQUIVALENT: dict[str, Excuse] = {part: excuse for excuse in EXCUSES for part in excuse.covers}

#: Words in a line that only a traceback through ros2nb or the ROS libraries shows.
THROUGH_LIBRARIES = ('site-packages', '/ros2nb/', 'rclpy/', '_rclpy', 'pybind11',
                     'incompatible function arguments', 'The grader could not finish',
                     '<locals>')
MOST_LINES = 3
#: Whole numbers up to this count what a check sent or heard (a burst's messages, their
#: numbers, readings, lines): a line may state them; a measurement (a decimal) it may not.
MOST_COUNTED = 100
#: Most characters of one answer's lines together: a line a learner reads at a glance.
MOST_CHARS = 400
#: Phrases that say nothing about the learner's code: what is wrong, or what to do.
GENERIC = ('something is wrong', 'is the machine very busy', 'fix it, then check again',
           'check the name against what', 'an error occurred', 'unexpected error',
           'see the traceback', 'try again')

_QUOTED = (re.compile(r'(?:^|\()\s*(?P<file>[\w.<> -]+?) line (?P<line>\d+): (?P<code>.+?)\)?$'),
           re.compile(r'at line (?P<line>\d+) \((?P<code>.+?)\)'))
_FRAME = re.compile(r'^\s*File "(?P<file>[^"]+)", line (?P<line>\d+)')
#: A number as a line states it (``-0.63``, ``1e+07``, ``22``), not part of a name.
NUMBER = re.compile(r'(?<![\w.])[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?![\w.]*\w)')
#: What a line may number without the learner's code producing it: its lines, parts,
#: notebooks, exit codes, arguments' positions, and what the grader itself set or sent.
_COUNTING = re.compile(r'(?:\bline|\blines|\bpart|\bparts|\bnotebook|\bcode|\bReading|'
                       r'\bargument|Challenge|\bstep)s? ?$|(?:\bgrader set [\w.]+ to|'
                       r'\bsetting [\w.]+ to|\bwhile [\w.]+ is|\bparam set [\w.]+|'
                       r'\bfor(?: a reading of)?) ?$',
                       re.I)
_MEANT = re.compile(r'did you mean (?:self\.)?([\w.]+)')
#: A line that is only Python's own error (its kind, its message).
_PYTHONS_OWN = re.compile(r'^(?:NameError|TypeError|AttributeError|ValueError|KeyError|'
                          r'IndexError|UnboundLocalError|AssertionError|SyntaxError|'
                          r'IndentationError|ZeroDivisionError|RuntimeError): ')


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


def _placeless(text: str) -> str:
    """``text`` without the places of the learner's code it quotes."""
    for pattern in _QUOTED:
        text = pattern.sub('', text)
    return text


def _unquoted(text: str) -> str:
    """``text`` without the learner's code it quotes (``(cell line 3: x = 1.5)``), nor the
    text it quotes in quotation marks (a log line, a name): what the line itself says."""
    for pattern in _QUOTED:
        text = pattern.sub(' ', text)
    return re.sub(r'(?<!\w)(?:"[^"]*"|\'[^\']*\'|`[^`]*`)(?!\w)', ' ', text)


def stated_numbers(lines: list[str], every: bool = False) -> list[tuple[float, float]]:
    """``(value, tolerance)`` of every number the answer states of its own: not the line
    numbers, parts or positions it counts, nor numbers inside the code or text it quotes
    (with ``every``, those too).  The tolerance is half the last digit shown (``22.31`` is
    22.305 to 22.315)."""
    found = []
    for line in lines:
        text = line if every else _unquoted(line)
        given: set[float] = set()  # what the grader set or sent, named again later in the line
        for match in NUMBER.finditer(text):
            shown = match.group()
            if not every and (_COUNTING.search(text[:match.start()]) or float(shown) in given):
                given.add(float(shown))
                continue
            decimals = len(shown.split('.')[1].split('e')[0]) if '.' in shown else 0
            found.append((float(shown), 0.5 * 10 ** -decimals + 1e-9))
    return found


def _numbers_in(text: str) -> set[float]:
    return {float(n) for n in NUMBER.findall(text)}


@lru_cache(maxsize=None)
def course_numbers() -> frozenset[float]:
    """The numbers a line may state as what is expected: the course's constants
    (``ros2nb.course``), how long each check runs the learner's code (simulated seconds) or
    waits for it, and every number in the notebooks' code (the constants the learner was
    given)."""
    from ros2nb import course, judge_interface
    from ros2nb.checks import lesson03, mains
    found = {float(v) for k, v in vars(course).items()
             if k.isupper() and isinstance(v, (int, float)) and not isinstance(v, bool)}
    found |= {float(v) for v in (lesson03.CONSTRUCTOR_RUN_S, lesson03.CALLBACK_RUN_S,
                                 lesson03.CLAMP_RUN_S, lesson03.HOUR_S, mains.START_PATIENCE_S,
                                 mains.EXIT_AFTER_CTRL_C_S, judge_interface.ARRIVAL_TIMEOUT_S)}
    for number in sorted({a.notebook for a in answers()}):
        for cell in notebook(number)['cells']:
            if cell['cell_type'] == 'code':
                found |= _numbers_in(''.join(cell['source']))
    return frozenset(found)


@lru_cache(maxsize=None)
def course_names(number: str) -> frozenset[str]:
    """Every name the course's notebook ``number`` defines or uses in its code (what a
    'did you mean' may suggest), and the course's own API."""
    import ros2nb
    found = set(dir(ros2nb))
    for cell in notebook(number)['cells']:
        if cell['cell_type'] == 'code':
            found |= _words(''.join(cell['source']))
    return frozenset(found)


@lru_cache(maxsize=None)
def imported(number: str) -> frozenset[str]:
    """The names notebook ``number``'s code imports (what an import's advice may be about)."""
    found: set[str] = set()
    for cell in notebook(number)['cells']:
        text = ''.join(cell['source']) if cell['cell_type'] == 'code' else ''
        for line in text.split('\n'):
            line = line.strip()
            if line.startswith(('import ', 'from ')):
                found |= {w.strip('(),') for w in line.replace(',', ' ').split()[1:]}
    return frozenset(found - {'import', 'as'})


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


def _parts(name: str) -> set[str]:
    """A name and its words of four letters and more (``QUEUE_DEPTH``: queue, depth), lower
    case."""
    words = re.split(r'_|(?<=[a-z])(?=[A-Z])', name)
    return {name.lower(), *(w.lower() for w in words if len(w) >= 4)}


#: A command-line flag (``--ros-args``, ``-r``): a name no word of a line is, said whole.
_FLAG = re.compile(r'-+[A-Za-z][\w-]*')


def _says_flag(flag: str, text: str) -> bool:
    """Whether ``text`` says ``flag`` as a whole, not inside a longer one (``-r`` inside
    ``--ros-args``)."""
    return re.search(rf'(?<![\w-]){re.escape(flag)}(?![\w-])', text) is not None


def names_change(outcome: dict, text: str) -> bool:
    """Whether ``text`` names what the mutant changed: it quotes a changed line, says a name
    (or a word of a name) the mutant changed, or a number it wrote."""
    lines = outcome['source'].split('\n')
    changed = [lines[i].strip() for i in outcome['changed'] if i < len(lines) and lines[i].strip()]
    if any(line in text or text_part in line for line in changed
           for _place, text_part in quoted_lines(text.split('\n')) if text_part):
        return True
    said = {w.lower() for w in _words(text)}
    # a changed value (a constant) changes no name: the names of its line say where it is
    affected = outcome['affected'] or sorted(_words(' '.join(changed)) - {'self'})
    if any(name in text if ' ' in name else _says_flag(name, text) if _FLAG.fullmatch(name)
           else any(word == part or (len(part) >= 4 and word.startswith(part))
                    for part in _parts(name) for word in said) for name in affected):
        return True
    written = set().union(*(_numbers_in(line) for line in changed)) if changed else set()
    return bool(written & _numbers_in(_unquoted(text)))


def _numbers_verdict(outcome: dict, shown: dict, text: str) -> list[str]:
    """Numbers the answer states that neither the learner's code produced, nor the learner
    wrote, nor the course gave as what is expected."""
    allowed = (_numbers_in(outcome['source']) | set(shown.get('produced', []))
               | course_numbers())
    return [f'it states {value:g}, a number the learner\'s code never produced'
            for value, tolerance in stated_numbers(text.split('\n'))
            if not (tolerance >= 0.5 and 0 <= value <= MOST_COUNTED)  # a count, an index
            and not any(abs(value - n) <= tolerance for n in allowed)]


def path_verdict(outcome: dict, shown: dict, *, judged: bool = True) -> tuple[str, list[str]]:
    """``('passed' | 'failed well' | 'bad', reasons)`` for one path's answer; with
    ``judged``, what it says is held to the promise too (not only its form): it names the
    change, states only numbers the learner's code produced, suggests only names the course
    defines, says something particular."""
    if shown['hung']:
        return 'bad', ['no answer: the check ran past its patience']
    if not shown['error']:
        return 'passed', []
    reasons = []
    lines = [line for line in shown['error'] if line.strip()]
    text = '\n'.join(lines)
    if len(lines) > MOST_LINES:
        reasons.append(f'{len(lines)} lines')
    said = _placeless(text)
    if len(said) > MOST_CHARS:
        reasons.append(f'{len(said)} characters (besides the code it quotes)')
    through = [word for word in THROUGH_LIBRARIES if any(word in line for line in lines)]
    if through:
        reasons.append(f'shows {through[0]!r}')
    for place, code in quoted_lines(lines):
        why = _blame(outcome, code, text)
        if why:
            reasons.append(f'{place}: {why}')
    if not judged:
        return ('bad' if reasons else 'failed well'), reasons
    lowered = text.lower()
    reasons += [f'says {phrase!r}, which tells nothing' for phrase in GENERIC if phrase in lowered]
    if _PYTHONS_OWN.match(lines[-1]) and not quoted_lines(lines):
        reasons.append("Python's own error, neither explained nor placed")
    if 'import it' in lowered and not set(outcome['affected']) & imported(outcome['notebook']):
        reasons.append('it tells to import a name, where the mutant touched no import')
    names = course_names(outcome['notebook'])
    reasons += [f'suggests {meant}, which the course does not define'
                for meant in _MEANT.findall(text) if meant.split('.')[-1] not in names]
    if outcome['operator'] != 'none' and not names_change(outcome, text):
        reasons.append('it names neither the changed line nor a name it changed')
    reasons += _numbers_verdict(outcome, shown, text)
    return ('bad' if reasons else 'failed well'), reasons


def message(shown: dict) -> str:
    """What one path's answer says, as two paths are compared: its last line without the
    error's kind, the places it quotes (a cell's line in the lab, the file's in the grader)
    nor the numbers it states (the readings of another run)."""
    lines = [line for line in shown['error'] if line.strip()]
    last = lines[-1] if lines else ''
    last = re.sub(r'^\w+: ', '', last)
    for pattern in _QUOTED:
        last = pattern.sub(' (...)', last)
    last = re.sub(r'\b(?:cell|[\w.]+\.py|answer) line \d+', 'line', last)
    return ' '.join(NUMBER.sub('#', last).split())


def verdict(outcome: dict) -> tuple[str, list[str]]:
    """``(verdict, reasons)``: ``'killed well'``, ``'survived (equivalent)'``,
    ``'survived (weak)'`` or ``'bad'``; for the unchanged answer, and the runs of it as
    written (:data:`PASSING_RUNS`), ``'passes'`` or ``'bad'``; with an earlier cell not run,
    the grader must pass it and the lab pass it or say which cell."""
    lab, lab_why = path_verdict(outcome, outcome['lab'])
    grading, grading_why = path_verdict(outcome, outcome['grading'])
    cell, cell_why = path_verdict(outcome, outcome['cell'], judged=False)
    reasons = [f'lab: {r}' for r in lab_why] + [f'grading: {r}' for r in grading_why]
    reasons += [f'the cell itself: {r}' for r in cell_why]
    if outcome['operator'] in ('none', *PASSING_RUNS):
        if lab == grading == 'passed':
            return 'passes', []
        return 'bad', reasons or ['the course\'s own answer fails its check']
    if outcome['operator'] == 'earlier cell not run':
        if grading != 'passed':
            return 'bad', [*reasons, 'the grader fails the answer as written']
        if reasons:
            return 'bad', reasons
        return ('passes', []) if lab == 'passed' else ('killed well', [])
    if (lab == 'passed') != (grading == 'passed'):
        passing = 'the lab' if lab == 'passed' else 'the grader'
        return 'bad', [f'only {passing} passes it', *reasons]
    if 'passed' not in (lab, grading) and not outcome['lab']['hung'] and \
            not outcome['grading']['hung'] and message(outcome['lab']) != message(
            outcome['grading']):
        reasons.append('the lab and the grader say different things')
    if reasons:
        return 'bad', reasons
    if lab == 'passed':
        reason = equivalent(outcome['ident'])
        return ('survived (equivalent)', [reason]) if reason else ('survived (weak)', [])
    return 'killed well', []


def equivalent(ident: str) -> Optional[str]:
    """Why the mutant named ``ident`` is no mistake, if an excuse (:data:`EXCUSES`) says."""
    return next((excuse.why for part, excuse in EQUIVALENT.items() if part in ident), None)
