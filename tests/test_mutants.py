"""A fixed sample of the mutation test (``make mistakes``): two mutants of every answer cell.

Each mutant runs as ``benchmarks/mistakes.py`` runs it (``mutation_runs.py``): in a real
kernel as the learner meets it, and through the grader's path; its answer must not be bad
(``mutation_verdicts.py``): one true line naming the change, the same in the lab and from the
grader, with what to do.  The sample was chosen from a full run: the two cheapest mutants of
each answer cell, of two operators.  Each excuse of ``mutation_verdicts.EXCUSES`` has its
witness run too: it must still survive both paths, as its reason says.  A planted bad
explanation (the learner's traceback in place of the line, as checks answered before issue
65) fails the same assertion.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from ros2nb import judge_interface
from ros2nb.errors import LearnerCodeError
from ros2nb.subject_replies import LearnerError

from mutation_runs import run_notebook
from mutation_verdicts import EXCUSES, verdict

pytestmark = [pytest.mark.kernel, pytest.mark.judge, pytest.mark.ros, pytest.mark.timeout(1800)]

#: Two mutants of every answer cell, by notebook (idents as ``make mistakes`` names them).
SAMPLE: dict[str, list[str]] = {
    '00': [
        '00-setup-and-the-pubsub-idea-challenge-1 | name one edit away |'
        ' .create_subscription -> .creat_subscription (line 6)',
        '00-setup-and-the-pubsub-idea-challenge-1 | method called, not passed'
        ' | self.shout -> self.shout() (line 7)',
    ],
    '01': [
        '01-create-a-workspace-challenge-1 | name one edit away | .expanduser'
        ' -> .expandusr (line 6)',
        '01-create-a-workspace-challenge-1 | statement deleted | return'
        " Path('~/Documents/ROS2_and_RL_Tutorials').expanduser( (line 6)",
    ],
    '02': [
        '02-create-a-package-challenge-1 | name one edit away | .parse ->'
        ' .pase (line 7)',
        '02-create-a-package-challenge-1 | import removed | import'
        ' xml.etree.ElementTree as ET (line 1)',
    ],
    '03': [
        '03-sensor-callback | local, not attribute | self.temperature = ->'
        ' temperature = (line 8)',
        '03-sensor-callback | statement deleted |'
        " self.get_logger().info(f'Publishing: {self.temperature:.2f}C (line"
        ' 13)',
        '03-sensor-constructor | arguments swapped |'
        ' self.create_timer(PUBLISH_PERIOD_S <-> self.publish_temperature)'
        ' (line 13)',
        '03-sensor-constructor | self. added | START_TEMPERATURE_C ->'
        ' self.START_TEMPERATURE_C (line 14)',
        '03-sensor-main | name one edit away | rclpy -> rcpy (line 8)',
        '03-sensor-main | statement deleted | rclpy.init(args=args) (line 8)',
    ],
    '04': [
        "04-monitor-callback | statement deleted | status = 'High' (line 10)",
        '04-monitor-callback | constant changed | LOW_BELOW_C -> 21.0 (line 11)',
        '04-monitor-constructor | self. added | TOPIC -> self.TOPIC (line 12)',
        '04-monitor-constructor | wrong message type | Float32 -> Float64'
        ' (line 12)',
        '04-monitor-main | name one edit away | node -> nde (line 7)',
        '04-monitor-main | statement deleted | node = TemperatureMonitor()'
        ' (line 7)',
    ],
    '05': [
        '05-entry-points | import removed | from setuptools import'
        ' find_packages, setup (line 2)',
        "05-entry-points | name one edit away | 'temperature_subscriber ="
        " sensor_simulator.temperature_subscriber:main':"
        ' sensor_simulator.temperature_subscriber -> ...temprature_subscriber'
        ' (line 29)',
        '05-setup-cfg | name one edit away | install_scripts -> installscripts',
        '05-setup-cfg | constant changed | install_scripts: $base/lib ->'
        ' $base/bin',
    ],
    '06': [
        "06-counting-monitor | name one edit away | TOPIC as 'temperature' ->"
        " 'temprature' (line 12)",
        '06-counting-monitor | method called, not passed | self.count ->'
        ' self.count() (line 12)',
        '06-fan-controller | arguments swapped | self.create_publisher(Bool'
        ' <-> FAN_TOPIC) (line 13)',
        '06-fan-controller | statement deleted |'
        ' self.publisher_.publish(command) (line 20)',
        '06-fan-main | statement deleted | rclpy.init(args=args) (line 6)',
        '06-fan-main | name one edit away | args -> ags (line 6)',
        '06-responsive-worker | return removed | return (node, executor) (line'
        ' 8)',
        '06-responsive-worker | statement deleted | executor ='
        ' MultiThreadedExecutor(num_threads=2) (line 7)',
        "06-room-arguments | name one edit away | '--ros-args' -> '--ro-args'"
        ' (line 5)',
        "06-room-arguments | statement deleted | return ['--ros-args', '-r',"
        " f'__ns:=/{room}'] (line 5)",
    ],
    '07': [
        '07-plot-callback | name one edit away | msg -> mg (line 7)',
        '07-plot-callback | self. dropped | self.get_clock -> get_clock (line'
        ' 6)',
    ],
    '08': [
        '08-monitor-parameters | constant changed | HIGH_ABOVE_C -> 27.0 (line'
        ' 15)',
        '08-monitor-parameters | self. dropped |'
        ' self.add_on_set_parameters_callback ->'
        ' add_on_set_parameters_callback (line 21)',
        '08-threshold-callback | name one edit away | parameter -> paramter'
        ' (line 7)',
        '08-threshold-callback | comparison flipped | low_c >= high_c -> low_c'
        ' <= high_c (line 10)',
    ],
    '09': [
        '09-qos-latched-thresholds | constant changed | 5 -> 2 (line 3)',
        '09-qos-latched-thresholds | name one edit away | .TRANSIENT_LOCAL ->'
        ' .TRANSINT_LOCAL (line 4)',
        '09-qos-newest-only | name one edit away | history= -> hisory= (line 3)',
        '09-qos-newest-only | statement deleted | return'
        ' QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1) (line 3)',
        '09-qos-sensor-subscription | name one edit away | QoSProfile ->'
        ' QoSPofile (line 3)',
        '09-qos-sensor-subscription | statement deleted | return'
        ' QoSProfile(depth=5, reliability=ReliabilityPolicy.BES (line 3)',
    ],
    '10': [
        '10-read-temperatures | constant changed | 1000000000.0 -> 1000000.0'
        ' (line 9)',
        '10-read-temperatures | self. added | TYPESTORE -> self.TYPESTORE'
        ' (line 4)',
        '10-record-hour | statement deleted | ros2nb.spin(HOUR_S,'
        ' show_logs=False) (line 7)',
        '10-record-hour | self. added | SEED -> self.SEED (line 3)',
        '10-replay | name one edit away | ros2nb -> ro2nb (line 3)',
        '10-replay | statement deleted | ros2nb.bag_play(bag_path, rate=rate,'
        " topics=['/temperature'] (line 4)",
    ],
}


#: Each excuse's witness, by notebook: run with the sample, it must survive.
WITNESSES: dict[str, set[str]] = {}
for _excuse in EXCUSES:
    WITNESSES.setdefault(_excuse.witness[:2], set()).add(_excuse.witness)


def answered_well(outcomes: list[dict]) -> None:
    """Fail, showing the answer, for any mutant answered badly, let through as weak, or, for a
    witness of an excuse, not let through."""
    witnesses = set().union(*WITNESSES.values())
    wrong = [(o['ident'], kind, why, (o['lab']['error'] or o['lab']['lines'])[-3:])
             for o in outcomes for kind, why in [verdict(o)]
             if kind not in ('killed well', 'passes', 'survived (equivalent)')
             or (o['ident'] in witnesses and kind != 'survived (equivalent)')]
    assert wrong == [], wrong


@pytest.mark.parametrize('number', sorted({*SAMPLE, *WITNESSES}))
def test_a_sample_of_mutants_is_answered_well(number, tmp_path):
    chosen = {*SAMPLE.get(number, ()), *WITNESSES.get(number, ())}
    outcomes = run_notebook(number, tmp_path / 'outcomes.jsonl', chosen, baseline=False)
    assert {o['ident'] for o in outcomes} == chosen  # none lost on the way
    answered_well(outcomes)


#: The planted mutant: a name one letter off in 03's constructor, which the check answers in
#: one line at the learner's line.
PLANTED = '03-sensor-constructor | name one edit away | QUEUE_DEPTH -> QUEU_DEPTH (line 12)'


def test_a_planted_bad_explanation_fails_the_sample(tmp_path, monkeypatch):
    """The judge words the learner's error as it did before issue 65 (their traceback, four
    lines and more): the sample's assertion fails, naming the mutant."""
    def traceback_instead(what: str, error: LearnerError, *, context: str = '') -> Exception:
        return LearnerCodeError(f'{what} raised{context}: {error.type}: {error.message}',
                                list(error.traceback))

    original = judge_interface.learner_error
    for module in list(sys.modules.values()):
        if module.__name__.startswith('ros2nb') and \
                getattr(module, 'learner_error', None) is original:
            monkeypatch.setattr(module, 'learner_error', traceback_instead)
    outcomes = run_notebook('03', Path(tmp_path) / 'planted.jsonl', {PLANTED}, baseline=False)
    assert [o['ident'] for o in outcomes] == [PLANTED]  # the operators still make it
    with pytest.raises(AssertionError, match='QUEU_DEPTH'):
        answered_well(outcomes)
