#!/usr/bin/env python3
"""How often 09's part-2 burst reaches a subscription with the learner's history whole.

``python benchmarks/qos_bursts.py [--checks N] [--depth D]`` runs the judge's part-2 check
(:func:`ros2nb.checks.lesson09.check_sensor_subscription`) N times on the solution's answer
with ``depth=D`` (a real judge session, the learner's subscription in a real subject, as the
grader runs it, then the burst to the judge's own subscription with its history) and prints
the verdicts and, per burst, whether it matched and came back whole
(:func:`ros2nb.checks.lesson09._whole`): a burst that did not is sent again, and these counts
say how often that happens.  Start two ``python3 -c 'while True: pass'`` beside it for a
busy machine.
"""

from __future__ import annotations

import argparse
import collections
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> None:
    """Run the checks; print one line per check and the counts at the end."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--checks', type=int, default=60)
    parser.add_argument('--depth', type=int, default=5)
    arguments = parser.parse_args()
    sys.path.insert(0, str(HERE.parent / 'tests'))
    from judging import answer_cells
    from ros2nb.checks import lesson09
    from ros2nb.errors import CheckFailed
    from ros2nb.judge.session import Session
    from ros2nb.judge_interface import AnswerRef

    context, answers = answer_cells(str(HERE.parent / 'solutions' / '09-qos.ipynb'))
    answer = answers['sensor_subscription_profile'].replace(
        'depth=5', f'depth={arguments.depth}')
    bursts: collections.Counter = collections.Counter()
    verdicts: collections.Counter = collections.Counter()
    burst = lesson09.qos.burst

    def counted(*args, **kwargs):  # type: ignore[no-untyped-def]  # burst() passed on
        out = burst(*args, **kwargs)
        bursts['whole' if out.matched and lesson09._whole(out.received) else
               f'matched={out.matched} kept={out.received}'] += 1
        return out

    lesson09.qos.burst = counted
    root = Path(tempfile.mkdtemp(prefix='qos-bursts-'))
    (root / 'ws').mkdir()
    session = Session(root / 'ws')
    try:
        for number in range(arguments.checks):
            session.observer.floods.forget()  # as every check of a class starts counting
            ref = AnswerRef('sensor_subscription_profile', (context, answer))
            try:
                verdict = 'passed: ' + lesson09._sensor_subscription(session, ref)
            except CheckFailed as failed:
                verdict = f'failed: {failed}'
            finally:
                session.drop(('cells', ref.sources))
            print(number, verdict[:110], flush=True)
            verdicts[verdict[:60]] += 1
    finally:
        session.close()
    print(dict(verdicts))
    print('bursts:', dict(bursts))


if __name__ == '__main__':
    main()
