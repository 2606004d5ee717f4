"""Checks of notebook 10, record and replay: the bag on disk and what a replay delivers.

Part of :mod:`ros2nb.checks`.  The learner writes three functions.  In the kernel they are
called there; the judge calls them from the learner's answer cells in a subject, whose ROS
runs on the judge's clock.  The verdict never comes from what they report.  While a
recording runs, the check hears ``/temperature`` and ``/rosout`` itself, each message with
the time it arrived (the judge's clock, or in the kernel the kernel's); it then reads the bag
itself with ``rosbags`` (a copy, once the learner's code is done) and compares: the bag must
hold what was on the wire, with the times it was there.  A replay is heard the same way:
the bag's readings, one second apart, and the monitor's status for each, in the same step.
The reading function is given a bag the check wrote itself, with readings of its own.
"""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path
from typing import Any, Callable, Optional

from .. import course, rules
from ..errors import CheckFailed
from ..runtime import current_runtime
from ..terminal import bag
from .answers import decoded, defined_verdict, result_of
from .bags import (CHECK_LOGGER, ROSOUT, TEMPERATURE, check_bag, check_readings_c, fresh_path,
                   bag_messages, read_back)
from ..judge_interface import ARRIVAL_TIMEOUT_S, AnswerRef, Judge
from ..subject_interface import Call
from ..subject_replies import Encoded, Output
from .base import call_learner, direct
from .drawn import chooser
from .witness import STATUS_LINE, Witness, witnessing

#: Rate the check replays at (simulated s per wall s): fast, and below what play reaches.
CHECK_RATE = 100.0
#: Steps of the judge's clock while the learner's function records or replays (s).
STEP_S = 1.0
#: Simulated seconds a function may keep its nodes running beyond what the task needs.
SPARE_S = 30.0
#: The notebook's sensor, seeded as the task says, for a few seconds: what the hour's first
#: readings must be (the context cell's names: random, SEED, pub, ros2nb).
SEEDED_S = 5
SEEDED = f'''
def _ros2nb_seeded_sensor():
    random.seed(SEED)
    ros2nb.add(pub.TemperatureSensor())
    ros2nb.spin({SEEDED_S}, show_logs=False)
    ros2nb.stop()
'''


# ------------------------------------------------------------------ calling the learner
def _call(judge: Optional[Judge], function: Any, label: str, *args: Any,
          spin_s: float = 0.0, stops: Optional[str] = None) -> Any:
    """Call the learner's function (in the kernel, or from source in a subject whose nodes
    run on the judge's clock for up to ``spin_s`` simulated seconds, in the judge's
    workspace with the course's nodes where the learner's are missing, as ``catch_up(10)``
    promises a notebook run on its own).

    :param stops: a node the function must have stopped by the time it returns (the judge
        waits for it to leave the ROS graph; the kernel looks at its own nodes).
    :raises CheckFailed: when it raised, or left ``stops`` running.
    """
    if isinstance(function, AnswerRef) and judge is not None:
        subject = judge.answer_subject(function,
                                       workspace=judge.answers_workspace(course.STEPS[10]))
        encoded = [{'path': str(a)} if isinstance(a, Path) else a for a in args]
        reply = judge.clock.drive(subject, Call(name=function.name, inputs=[encoded]),
                                  step_s=STEP_S, limit_s=spin_s + SPARE_S, what=label)
        defined_verdict(reply, function.name)
        returned = result_of(reply.outputs[0] if reply.outputs else Output(error=reply.error),
                             label)
        observer = judge.observer
        left = stops is not None and not observer.wait_until(
            lambda: not observer.has_node(stops), ARRIVAL_TIMEOUT_S)
        judge.drop_all()  # its nodes leave the graph: what they said is heard by now
        if left:
            raise CheckFailed(_LEFT_RUNNING.format(label=label, node=stops))
        return _plain(returned)
    if spin_s:  # the function runs nodes: none of an earlier cell's may run beside them
        _no_nodes_left(label)
    with contextlib.redirect_stdout(io.StringIO()):  # the verdict is the check's line alone
        result = call_learner(function, *args, label=label)
    rt = current_runtime()
    if stops is not None and rt is not None and rt.nodes:
        remaining = sorted(rt.nodes)  # named as the grader names the node it waits for
        running = stops if any(n.rsplit('/', 1)[-1] == stops for n in remaining) \
            else ', '.join(remaining)
        rt.stop()  # the next check's call must start with no node of this one
        raise CheckFailed(_LEFT_RUNNING.format(label=label, node=running))
    return result


#: The line for a function that left a node it should have stopped.
_LEFT_RUNNING = ('{label} returned with {node} still running: end it with ros2nb.stop(), as '
                 'the task says, so that it stops the nodes it added.')


def _no_nodes_left(label: str) -> None:
    """In the kernel: nodes an earlier cell left running would publish and log beside what
    the learner's function makes; say so, before it runs, instead of blaming the function."""
    rt = current_runtime()
    left = sorted(rt.nodes) if rt is not None else []
    if left:
        raise CheckFailed(f'{len(left)} node(s) from earlier cells are still running in this '
                          f'kernel ({", ".join(left)}): what they publish and log would mix '
                          f'with what {label} makes. Run ros2nb.stop(), then this check again '
                          '(and end your function with ros2nb.stop(), so it leaves none).')


def _plain(result: Encoded) -> Any:
    """A subject's encoded value as plain Python (lists of lists and numbers kept)."""
    if isinstance(result.value, list):
        return [_plain(item) for item in result.value]
    return decoded(Output(result=result), '')


# ------------------------------------------------------------------ part 1: the recording
def _bag_verdict(path: Path, label: str) -> dict[str, int]:
    """The bag's own facts, or the one line saying what is wrong with it."""
    if not path.is_dir():
        raise CheckFailed(f'{label} wrote no bag at the path it was given: pass bag_path to '
                          'bag_record as its output.')
    info = bag.metadata(path)
    if info.get('storage_identifier') != bag.STORAGE_ID:
        raise CheckFailed(f'The bag is stored as {info.get("storage_identifier")}, not mcap: '
                          'record it with ros2nb.bag_record.')
    topics = {t['topic_metadata']['name']: t for t in info['topics_with_message_count']}
    for topic, why in ((TEMPERATURE, 'the readings'), (ROSOUT, "the monitor's statuses")):
        if topic not in topics:
            raise CheckFailed(f'The bag holds {", ".join(topics) or "no topic"} but not {topic} '
                              f'({why}): record both {TEMPERATURE} and {ROSOUT}.')
    kind = topics[TEMPERATURE]['topic_metadata']['type']
    if kind != course.MESSAGE_TYPE:
        raise CheckFailed(f'{TEMPERATURE} is recorded as {kind}, expected {course.MESSAGE_TYPE}.')
    return {t: v['message_count'] for t, v in topics.items()}


def _recording(judge: Optional[Judge], record_hour: Any) -> str:
    label = f'{record_hour.__name__}(bag_path)'
    with fresh_path(judge, 'hour') as path:
        with witnessing(judge) as seen:
            _call(judge, record_hour, label, path, spin_s=course.RECORD_S,
                  stops=course.SENSOR_NODE)  # the task ends the hour with ros2nb.stop()
        if not path.is_dir():
            _bag_verdict(path, label)  # the line for "no bag at all"
        with read_back(judge, path) as copy:
            verdict = _recording_verdict(copy, label, seen)
    _seed_verdict(judge, record_hour, label, [value for _t, value in seen.readings])
    return verdict


def _seed_verdict(judge: Optional[Judge], record_hour: Any, label: str,
                  hour: list[float]) -> None:
    """The hour must be the one ``random.seed(SEED)`` gives (the same on every run): its
    first readings are what the notebook's sensor publishes right after that seed, as the
    check hears it.  Without the notebook's names (SEED, pub) there is nothing to compare."""
    if isinstance(record_hour, AnswerRef):
        probe: Any = AnswerRef('_ros2nb_seeded_sensor', (*record_hour.sources, SEEDED))
    else:
        names = dict(record_hour.__globals__)
        if not all(name in names for name in ('random', 'SEED', 'pub', 'ros2nb')):
            return
        exec(SEEDED, names)  # noqa: S102 - the course's own lines, in a copy of the names
        probe = names['_ros2nb_seeded_sensor']
    try:
        with witnessing(judge) as seen:
            _call(judge, probe, 'the seeded sensor', spin_s=SEEDED_S)
    except CheckFailed:
        return  # the notebook's names are not what the course gave: no comparison
    seeded = [value for _t, value in seen.readings]
    if seeded and [round(v, 3) for v in hour[:len(seeded)]] != [round(v, 3) for v in seeded]:
        got, want = (', '.join(f'{v:.2f}' for v in values[:3]) for values in (hour, seeded))
        raise CheckFailed(f'{label} recorded an hour starting {got} °C, but the sensor seeded '
                          f'with random.seed(SEED) starts {want} °C: call random.seed(SEED) in '
                          'record_hour before the hour runs, so that it is the same hour on '
                          'every run.')


def _recording_verdict(path: Path, label: str, seen: Witness) -> str:
    """The bag at ``path`` against an hour of the sensor and the monitor, and against what
    the check heard on the wire meanwhile."""
    _bag_verdict(path, label)
    hour = round(course.RECORD_S / course.PUBLISH_PERIOD_S)
    heard = seen.readings
    if len(heard) != hour:
        raise CheckFailed(f'{len(heard)} readings went out on {TEMPERATURE} while '
                          f'{label} ran; one simulated hour of the sensor is {hour}: add both '
                          f'nodes, then record while spinning {course.RECORD_S:g} s.')
    recorded = [(stamp, float(m.data)) for stamp, m in bag_messages(path, TEMPERATURE)]
    if len(recorded) != len(heard):
        raise CheckFailed(f'The bag holds {len(recorded)} readings on {TEMPERATURE}, but '
                          f'{len(heard)} went out while it recorded: record while the nodes '
                          'spin, and stop recording after.')
    for index, ((stamp, value), (t_ns, sent)) in enumerate(zip(recorded, heard), start=1):
        if not math.isclose(value, sent, abs_tol=1e-4):
            raise CheckFailed(f'Reading {index} of the bag is {value:.2f} °C, but {sent:.2f} °C '
                              f'went out on {TEMPERATURE}: record the messages as they are, '
                              'with ros2nb.bag_record.')
        if stamp != t_ns:
            raise CheckFailed(f'Reading {index} of the bag is stamped {stamp / 1e9:g} s, but it '
                              f'went out at {t_ns / 1e9:g} s of simulated time: record while the '
                              'nodes spin, with ros2nb.bag_record (it stamps each message with '
                              'the clock).')
    lines = [STATUS_LINE.fullmatch(m.msg) for _s, m in bag_messages(path, ROSOUT)
             if m.name == course.MONITOR_NODE]
    in_bag = [(float(m.group(1)), m.group(2)) for m in lines if m]
    said = seen.statuses()
    _statuses_follow_readings(said, heard, label)
    if in_bag != [(r, s) for _t, r, s in said]:
        raise CheckFailed(f'The bag holds {len(in_bag)} status lines of {course.MONITOR_NODE} on '
                          f'{ROSOUT}, but the monitor said {len(said)} while it recorded: record '
                          f'{ROSOUT} too, from before the spin to after it.')
    return (f'the bag is MCAP with metadata.yaml: the {hour} readings ({course.MESSAGE_TYPE}) '
            f'and the {hour} statuses of {course.MONITOR_NODE} on {ROSOUT} that went out, '
            'each stamped with its time.')


def _statuses_follow_readings(said: list[tuple[int, float, str]],
                              heard: list[tuple[int, float]], label: str) -> None:
    """One status per reading, the reading's own, in the same step of the clock: the
    monitor heard each reading (a node that logs statuses of its own accord does not)."""
    if not said:
        raise CheckFailed(f'{course.MONITOR_NODE} logged no status while {label} ran: add your '
                          'monitor, so it hears the readings.')
    by_step: dict[int, list[tuple[float, str]]] = {}
    for t, r, s in said:  # grouped once: an hour's 3600 readings each looked up, not searched
        by_step.setdefault(t, []).append((r, s))
    for index, (t_ns, value) in enumerate(heard, start=1):
        mine = by_step.get(t_ns, [])
        want = (round(value, 2), rules.monitor_status(value))
        if len(mine) != 1 or (round(mine[0][0], 2), mine[0][1]) != want:
            got = ', '.join(f'{r:.2f} {s}' for r, s in mine) or 'nothing'
            raise CheckFailed(f'For reading {index} ({value:.2f} °C, at {t_ns / 1e9:g} s) '
                              f'{course.MONITOR_NODE} said {got}; it should say '
                              f'{want[1]} for it, once, as it hears it: add the monitor once, '
                              f'and let it hear {TEMPERATURE}.')
    if len(said) != len(heard):
        raise CheckFailed(f'{course.MONITOR_NODE} logged {len(said)} statuses for the '
                          f'{len(heard)} readings: one per reading, from one monitor.')


@direct
def check_recording(judge: Optional[Judge], record_hour: Any) -> str:
    """Check part 1 of notebook 10: one simulated hour recorded into an MCAP bag.

    Calls your function with a folder that does not exist yet and listens meanwhile to
    ``/temperature`` and ``/rosout`` itself; then reads the bag: MCAP storage with a
    ``metadata.yaml``, the 3600 readings (``std_msgs/msg/Float32``) that went out, each with
    the time it went out, and the 3600 status lines ``temperature_monitor`` logged for them.

    Introduced in ``10-record-and-replay.ipynb``.

    :param record_hour: your function (no parentheses).
    :raises CheckFailed: naming what the bag lacks.
    """
    return _recording(judge, record_hour)


# ------------------------------------------------------------------ part 2: the replay
def _replay(judge: Optional[Judge], replay: Any) -> str:
    readings = check_readings_c(chooser(judge, '10 replay').getrandbits(32))
    with check_bag(judge, 'sixty', readings) as path:
        with witnessing(judge) as seen:
            _call(judge, replay, f'{replay.__name__}(bag_path, rate)', path, CHECK_RATE,
                  spin_s=len(readings) * course.PUBLISH_PERIOD_S, stops=course.MONITOR_NODE)
    return _replay_verdict(readings, seen, f'{replay.__name__}(bag_path, rate)')


def _replay_verdict(readings: list[float], seen: Witness, label: str) -> str:
    sent = len(readings)
    if any(name == CHECK_LOGGER for _t, name, _text in seen.lines):
        raise CheckFailed(f'{label} played the bag\'s {ROSOUT} too: play only {TEMPERATURE} '
                          f"(topics=['{TEMPERATURE}']); old log lines are a record, not input.")
    heard = seen.readings
    if [round(v, 2) for _t, v in heard] != [round(v, 2) for v in readings]:
        raise CheckFailed(f'{len(heard)} readings went out on {TEMPERATURE} during the replay; '
                          f'the bag holds {sent}: play the bag\'s {TEMPERATURE}, all of it, '
                          'once.')
    gaps = {round((b - a) / 1e9, 6) for (a, _v), (b, _w) in zip(heard, heard[1:])}
    if gaps != {course.PUBLISH_PERIOD_S}:
        raise CheckFailed(f'The replayed readings came {sorted(gaps)} s apart on the clock; the '
                          f'bag recorded them {course.PUBLISH_PERIOD_S} s apart: replay with '
                          'ros2nb.bag_play, which keeps the recorded gaps.')
    said = seen.statuses()
    if not said:
        raise CheckFailed(f'{course.MONITOR_NODE} logged no status during the replay: add your '
                          'monitor before bag_play, so it hears the replayed readings.')
    _statuses_follow_readings(said, heard, label)
    return (f'{sent} replayed readings reached {course.MONITOR_NODE}, one second apart, and it '
            f'logged the status each calls for, as it heard it.')


@direct
def check_replay(judge: Optional[Judge], replay: Any) -> str:
    """Check part 2 of notebook 10: a bag replayed into the monitor gives its statuses again.

    Writes a bag of 60 readings of its own, calls ``replay(bag_path, rate)`` and listens
    itself: every reading must go out on ``/temperature``, one second apart, and your
    monitor must log, as it hears each one, the status it calls for, once.

    Introduced in ``10-record-and-replay.ipynb``.

    :param replay: your function (no parentheses).
    :raises CheckFailed: naming what the replay delivered instead.
    """
    return _replay(judge, replay)


# ------------------------------------------------------------------ part 3: reading a bag
def _readings(judge: Optional[Judge], read_temperatures: Any) -> str:
    readings = check_readings_c(chooser(judge, '10 readings').getrandbits(32))
    with check_bag(judge, 'sixty', readings) as path:
        return _readings_in(judge, path, read_temperatures, readings)


def _readings_in(judge: Optional[Judge], path: Path, read_temperatures: Any,
                 readings: list[float]) -> str:
    got = _call(judge, read_temperatures, f'{read_temperatures.__name__}(bag_path)', path)
    name = f'{getattr(read_temperatures, "__name__", "your function")}()'
    if not (isinstance(got, (list, tuple)) and len(got) == 2
            and all(isinstance(side, (list, tuple)) for side in got)):
        raise CheckFailed(f'{name} returned {type(got).__name__}; return two lists: '
                          '(times_s, temperatures_c).')
    times, values = (list(side) for side in got)
    sent = len(readings)
    if len(values) != sent or len(times) != sent:
        raise CheckFailed(f'{name} returned {len(times)} times and {len(values)} readings; the '
                          f'bag holds {sent} on {TEMPERATURE} (and one message on {ROSOUT}: '
                          f'keep only {TEMPERATURE}).')
    want_times = [float(k) for k in range(sent)]
    if not all(isinstance(t, (int, float)) and abs(t - w) < 1e-6
               for t, w in zip(times, want_times)):
        raise CheckFailed(f'{name} returned times {times[:3]}...; expected seconds since the '
                          f'first reading, [0.0, 1.0, 2.0, ...]: (stamp - first stamp) / 1e9.')
    if not all(isinstance(v, (int, float)) and abs(v - w) < 1e-4
               for v, w in zip(values, readings)):
        said = 'messages, not their data;' if 'data' in repr(values[:1]) else f'{values[:3]}...;'
        raise CheckFailed(f'{name} returned readings {said} expected the messages\' data, '
                          f'{readings[:3]}...: deserialize each message and take its field, .data.')
    return f'{name} returns the {sent} readings of the bag, with their times from 0 s.'


@direct
def check_readings(judge: Optional[Judge], read_temperatures: Callable[..., Any]) -> str:
    """Check part 3 of notebook 10: a bag's readings read back with rosbags.

    Writes a bag of 60 readings of its own, one second apart (and one ``/rosout`` line),
    calls your function and compares: times in seconds since the first reading, and every
    value.

    Introduced in ``10-record-and-replay.ipynb``.

    :param read_temperatures: your function (no parentheses).
    :raises CheckFailed: naming what your function returned instead.
    """
    return _readings(judge, read_temperatures)
