"""Checks of notebook 09, QoS: what subscriptions with the learner's profiles really receive.

Part of :mod:`ros2nb.checks`.  The learner writes functions that return a ``QoSProfile``.
In the kernel the function is called there; the judge calls it from the learner's answer
cell in a subject, which sends back only the profile's policies (plain names and numbers).
Either way the check then runs a real publisher and subscription with that profile
(:mod:`ros2nb.qos`, on a private context) and judges the numbers delivered, never the
source text.
"""

from __future__ import annotations

from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, qos_profile_sensor_data

from .. import qos
from ..errors import CheckFailed
from .answers import answer_results, decoded, type_name_of
from .base import AnswerRef, call_learner, current_judge, passed

#: The burst of part 1 and what a display of the newest reading must be left with.
BURST = 30
NEWEST = [BURST - 1]
#: Part 3: thresholds published before the late joiner, and the last ones it must get.
LATCHED_SENT, LATCHED_KEPT = 20, 5
LATCHED = list(range(LATCHED_SENT - LATCHED_KEPT, LATCHED_SENT))
#: Part 2: readings the sensor publishes once matched.
READINGS = 5
#: The sensor's publisher of part 2: rclpy's sensor-data preset (best effort, depth 5).
SENSOR_QOS = qos_profile_sensor_data


def learner_profile(make_profile: Any) -> QoSProfile:
    """The profile the learner's function returns (called in the kernel or in a subject).

    :raises CheckFailed: when it raises, or returns anything but a QoSProfile.
    """
    if isinstance(make_profile, AnswerRef):
        profile = decoded(answer_results(make_profile, [[]])[0], f'{make_profile.name}()')
        # The trials run on the judge's domain: nothing of the learner's (a thread their
        # answer cell started) may be left to publish on a trial's topic.
        current_judge().drop_all()
    else:
        profile = call_learner(make_profile)
    if not isinstance(profile, QoSProfile):
        raise CheckFailed(f'{make_profile.__name__}() returned {type_name_of(profile)} '
                          f'{profile!r}; return a QoSProfile(...).')
    return profile


def _span(received: list[int]) -> str:
    if len(received) <= 3:
        return str(received)
    return f'[{received[0]}, {received[1]}, ..., {received[-1]}]'


def _newest_only(make_profile: Any) -> str:
    profile = learner_profile(make_profile)
    got = qos.burst(profile, count=BURST)
    if not got.matched:
        raise CheckFailed(f'Your subscription ({qos.describe(profile)}) never matched the '
                          f'reliable, volatile publisher: {got.explanation}')
    if got.received == NEWEST:
        return (f'after a burst of {BURST}, a subscription with {qos.describe(profile)} '
                f'is left with {NEWEST}: the newest reading only.')
    if profile.history == HistoryPolicy.KEEP_ALL:
        raise CheckFailed(f'After a burst of {BURST} your subscription got all '
                          f'{len(got.received)}: KEEP_ALL keeps every message; use KEEP_LAST '
                          'with depth=1.')
    raise CheckFailed(f'After a burst of {BURST} your subscription got '
                      f'{len(got.received)} messages {_span(got.received)}: its history '
                      'keeps that many; a display of the newest reading keeps depth=1.')


def check_newest_only(make_profile: Any) -> None:
    """Check part 1 of notebook 09: a subscription profile that keeps only the newest reading.

    A reliable publisher sends a burst of 30 numbers (0 to 29) before the subscription's
    callback runs once; a subscription with your profile must be left with ``[29]``.

    Introduced in ``09-qos.ipynb``.

    :param make_profile: your function returning the profile (no parentheses).
    :raises CheckFailed: naming what the subscription got instead.
    """
    passed(_newest_only(make_profile))


def _latched(make_profile: Any) -> str:
    profile = learner_profile(make_profile)
    got = qos.late_joiner(profile, count=LATCHED_SENT)
    where = (f'A subscription that joined after {LATCHED_SENT} thresholds were published '
             f'(0 to {LATCHED_SENT - 1})')
    if got.received == LATCHED:
        return (f'with {qos.describe(profile)} a late joiner gets the last {LATCHED_KEPT} of '
                f'{LATCHED_SENT}: {LATCHED}.')
    if not got.received and profile.durability != DurabilityPolicy.TRANSIENT_LOCAL:
        raise CheckFailed(f'{where} got none: make durability TRANSIENT_LOCAL, so the publisher '
                          'keeps its last messages for late joiners.')
    if not got.received:
        raise CheckFailed(f'{where} got none: it is {qos.describe(profile)}, and a best-effort '
                          'subscription is not sent what was published before it joined: make '
                          'it RELIABLE.')
    if profile.history == HistoryPolicy.KEEP_ALL:
        raise CheckFailed(f'{where} got all {len(got.received)}: KEEP_ALL keeps every message; '
                          f'keep the last {LATCHED_KEPT} (KEEP_LAST, depth={LATCHED_KEPT}).')
    raise CheckFailed(f'{where} got {len(got.received)} {_span(got.received)}, expected the '
                      f'last {LATCHED_KEPT} {_span(LATCHED)}: depth={LATCHED_KEPT}.')


def check_latched_thresholds(make_profile: Any) -> None:
    """Check part 3 of notebook 09: a "latched" profile that late joiners still hear.

    A publisher with your profile publishes 20 numbers with nobody listening; then a
    subscription with your profile joins.  It must get exactly the last five, 15 to 19.

    Introduced in ``09-qos.ipynb``.

    :param make_profile: your function returning the profile (no parentheses).
    :raises CheckFailed: naming what the late joiner got instead.
    """
    passed(_latched(make_profile))


def _sensor_subscription(make_profile: Any) -> str:
    profile = learner_profile(make_profile)
    got = qos.pair(SENSOR_QOS, profile, count=READINGS)
    sensor = qos.describe(SENSOR_QOS)
    if not got.matched:
        raise CheckFailed(f'Incompatible QoS: the sensor publishes with {sensor}, your '
                          f'subscription asks for {qos.describe(profile)}; '
                          f'{got.explanation or "they never matched."}')
    return (f'a subscription with {qos.describe(profile)} matches the sensor ({sensor}): '
            'no incompatible-QoS event.')


def check_sensor_subscription(make_profile: Any) -> None:
    """Check part 2 of notebook 09: a subscription profile the best-effort sensor can serve.

    A publisher with rclpy's sensor-data preset (best effort, keep last 5, volatile) meets a
    subscription with your profile: rclpy's incompatible-QoS event must not fire, and the two
    must match.

    Introduced in ``09-qos.ipynb``.

    :param make_profile: your function returning the profile (no parentheses).
    :raises CheckFailed: with the one-line reason when the pair is incompatible.
    """
    passed(_sensor_subscription(make_profile))
