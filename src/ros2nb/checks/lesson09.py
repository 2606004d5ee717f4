"""Checks of notebook 09, QoS: what endpoints made with the learner's profiles really do.

Part of :mod:`ros2nb.checks`.  The learner writes functions that return a ``QoSProfile``.
In the kernel the function is called there and the trials of :mod:`ros2nb.qos` run on a
private context.  The judge calls it from the learner's answer cell in a subject, which makes
a subscription or a publisher with the very profile it returned; the judge then sees, itself,
what that endpoint does: the profile discovery reports for it (as ``ros2 topic info
--verbose`` shows it), whether the judge's publisher matches it (rclpy's
``qos_check_compatible`` names why not), and what a late joiner of the judge's receives from
it.  What a subscription keeps of a burst is its history's doing: the judge sees what a
subscription of its own with that history and depth keeps (discovery does not carry them;
the subject says what the function returned).  Either way the same rules decide.
"""

from __future__ import annotations

import copy
import secrets
from typing import Any, Optional

from rclpy.qos import (DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy,
                       qos_profile_sensor_data)
from std_msgs.msg import Int32

from .. import qos
from ..explain.ros_settings import zero_depth_refused
from ..errors import CheckFailed, NotDecided
from .answers import defined_verdict, type_name_of
from ..judge_interface import ARRIVAL_TIMEOUT_S, AnswerRef, Judge, learner_error
from ..subject_interface import QosAcked, QosEndpoint
from ..subject_replies import QosMade
from .base import call_learner, direct

#: The burst of part 1 and what a display of the newest reading must be left with.
BURST = 30
NEWEST = [BURST - 1]
#: Part 3: thresholds published before the late joiner, and the last ones it must get.
LATCHED_SENT, LATCHED_KEPT = 20, 5
LATCHED = list(range(LATCHED_SENT - LATCHED_KEPT, LATCHED_SENT))
#: Part 2: readings the sensor publishes once matched, and what the subscription keeps of a
#: burst it fell behind on: the last five.
READINGS = 5
SENSOR_KEPT = list(range(BURST - 5, BURST))
#: Bursts the judge sends to a reliable subscription before it says the machine kept one
#: from arriving whole (docs/decisions.md): the learner's profile never decides that.
BURST_TRIES = 3
#: The sensor's publisher of part 2: rclpy's sensor-data preset (best effort, depth 5).
SENSOR_QOS = qos_profile_sensor_data


def learner_profile(make_profile: Any) -> QoSProfile:
    """The profile the learner's function returns, called in the kernel (never in a judge).

    :raises CheckFailed: when it raises, or returns anything but a QoSProfile.
    """
    with zero_depth_refused():
        profile = call_learner(make_profile)
    if not isinstance(profile, QoSProfile):
        raise CheckFailed(f'{make_profile.__name__}() returned {type_name_of(profile)} '
                          f'{profile!r}; return a QoSProfile(...).')
    return profile


def _span(received: list[int]) -> str:
    if len(received) <= 3:
        return str(received)
    return f'[{received[0]}, {received[1]}, ..., {received[-1]}]'


# ------------------------------------------------------------------ the judge's side
class _Endpoint:
    """An endpoint with the learner's profile, made in a subject on a topic of the judge's,
    and the judge's view of it."""

    def __init__(self, judge: Judge, ref: AnswerRef, kind: str,
                 numbers: tuple[int, ...] = ()) -> None:
        judge.drop_all()  # nothing of the learner's left to publish on a trial's topic
        self.judge, self.observer = judge, judge.observer
        self.topic = f'/ros2nb_qos_trial_{secrets.token_hex(4)}'
        self.subject = judge.answer_subject(ref)
        reply = self.subject.request(QosEndpoint(name=ref.name, topic=self.topic, kind=kind,
                                                 numbers=list(numbers)))
        defined_verdict(reply, ref.name)
        if reply.error is not None:
            raise learner_error(f'{ref.name}()', reply.error)
        if reply.returned is not None:
            returned = reply.returned
            raise CheckFailed(f'{ref.name}() returned {returned.type} {returned.value}; '
                              'return a QoSProfile(...).')
        found = qos.discovered(self.observer.node, self.topic, kind,
                               seconds=ARRIVAL_TIMEOUT_S)
        if not found:
            raise CheckFailed(f'The grader could not see the {kind} made with your profile within '
                              f'{ARRIVAL_TIMEOUT_S:g} s (is the machine very busy?): run this '
                              'check again.')
        #: The endpoint's profile as discovery reports it (history and depth: not carried).
        self.profile: QoSProfile = found[0].qos_profile
        #: A reliable, volatile profile with the history and depth the learner's function
        #: returned, as the subject read them: what a subscription of the judge's keeps with
        #: it is what the learner's keeps (:func:`_kept`).
        self.history = _history_of(reply)

    def close(self) -> None:
        self.judge.drop_all()


def _history_of(reply: QosMade) -> QoSProfile:
    """The reliable, volatile profile with the history and depth of a subject's reply; a
    depth past the burst keeps what the burst's own length would (all of it)."""
    try:
        if reply.history is None or reply.depth is None:
            raise ValueError('no history or depth')
        history = HistoryPolicy(reply.history)
        depth = min(max(reply.depth, 0), BURST + 1)
    except ValueError:
        raise CheckFailed('The grader could not read the history and depth of your profile '
                          'from the trial (its process was disturbed): run this check again.'
                          ) from None
    return QoSProfile(history=history, depth=depth)


def _whole(received: list[int]) -> bool:
    """Whether a reliable subscription got the whole burst: every profile keeps at least the
    newest of it, and the newest ones in a row (KEEP_LAST: its depth; KEEP_ALL: all)."""
    return bool(received) and received == list(range(BURST - len(received), BURST))


def _kept(history: QoSProfile) -> qos.Deliveries:
    """What a reliable subscription with ``history`` keeps of a burst of :data:`BURST` while
    its callback is busy: the trial of :func:`ros2nb.qos.burst`, in this process (the
    kernel's, or the judge's own, never a subject's).  A burst that did not arrive whole met
    a busy machine, not the profile: it is sent again, to a new subscription.

    :raises NotDecided: when that happened :data:`BURST_TRIES` times.
    """
    for _ in range(BURST_TRIES):
        got = qos.burst(_reliable(history), count=BURST)
        if got.matched and _whole(got.received):
            return got
    raise NotDecided(f'the grader\'s burst of {BURST} never reached a subscription with your '
                     f'profile whole in {BURST_TRIES} tries')


def _judged_match(judge: Judge, ref: AnswerRef,
                  offered: QoSProfile) -> tuple[qos.Deliveries, QoSProfile, QoSProfile]:
    """Does a publisher of the judge's with ``offered`` match the subscription the learner's
    profile made in a subject?  rclpy decides from both profiles as discovery reports them.

    :return: whether it matched (or why not), that subscription's profile as discovery
        reports it, and its history and depth (:attr:`_Endpoint.history`).
    """
    endpoint = _Endpoint(judge, ref, 'subscription')
    node = endpoint.observer.node
    publisher = node.create_publisher(Int32, endpoint.topic, offered)
    out = qos.Deliveries()
    try:
        sender = qos.discovered(node, endpoint.topic, 'publisher')
        out.explanation = qos.incompatibility(sender[0].qos_profile if sender else offered,
                                              endpoint.profile)
        if out.explanation is None:
            out.matched = endpoint.observer.wait_until(
                lambda: publisher.get_subscription_count() >= 1, ARRIVAL_TIMEOUT_S)
    finally:
        node.destroy_publisher(publisher)
        endpoint.close()
    return out, endpoint.profile, endpoint.history


def _judged_burst(judge: Judge, ref: AnswerRef) -> tuple[qos.Deliveries, QoSProfile]:
    """Part 1: the learner's subscription meets the judge's reliable, volatile publisher;
    when they match, what a subscription with its history keeps of the burst."""
    out, profile, history = _judged_match(judge, ref, QoSProfile(depth=BURST))
    if out.matched:
        out.received = _kept(history).received
    return out, profile


def _judged_late_joiner(judge: Judge, ref: AnswerRef) -> tuple[qos.Deliveries, QoSProfile]:
    """Part 3: a publisher with the learner's profile publishes 20 numbers; then the judge's
    subscription joins, with that profile as discovery reports it (keeping all it is sent),
    and the judge counts what it got once the publisher says everything was acknowledged."""
    # Numbers only the judge knows, so that what the joiner gets is what this publisher
    # kept: anything else on the topic (a thread of the answer cell's) is seen as such.
    sent = tuple(secrets.randbelow(2**31 - 1) for _ in range(LATCHED_SENT))
    endpoint = _Endpoint(judge, ref, 'publisher', numbers=sent)
    profile = endpoint.profile
    joiner = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=profile.reliability,
                        durability=profile.durability, deadline=profile.deadline,
                        lifespan=profile.lifespan, liveliness=profile.liveliness,
                        liveliness_lease_duration=profile.liveliness_lease_duration)
    taker = endpoint.observer.quiet_node()  # takes only when told: nothing is missed
    subscription = taker.create_subscription(Int32, endpoint.topic, lambda msg: None, joiner)
    out = qos.Deliveries()
    try:
        out.matched = endpoint.observer.wait_until(
            lambda: subscription.get_publisher_count() >= 1, ARRIVAL_TIMEOUT_S)
        if out.matched:
            endpoint.subject.request(QosAcked(seconds=ARRIVAL_TIMEOUT_S),
                                     timeout=ARRIVAL_TIMEOUT_S + 10)
            taken = _take_all(subscription)
            if any(number not in sent for number in taken) or \
                    len(endpoint.observer.node.get_publishers_info_by_topic(endpoint.topic)) != 1:
                raise CheckFailed('Something other than the publisher made with your profile '
                                  'published on the check\'s topic: an answer cell defines the '
                                  'function only; start no node or thread in it.')
            out.received = [sent.index(number) for number in taken]
    finally:
        taker.destroy_subscription(subscription)
        endpoint.close()
    return out, profile


def _take_all(subscription: Any) -> list[int]:
    """Every number waiting in a subscription's history, taken at once."""
    taken = []
    with subscription.handle:
        while (got := subscription.handle.take_message(subscription.msg_type,
                                                        subscription.raw)) is not None:
            taken.append(got[0].data)
    return taken


# ------------------------------------------------------------------ the three parts
def _newest_only(judge: Optional[Judge], make_profile: Any) -> str:
    if isinstance(make_profile, AnswerRef) and judge is not None:
        got, profile = _judged_burst(judge, make_profile)
        shown = 'your profile'
        keeps_all = None
    else:
        profile = learner_profile(make_profile)
        got = qos.burst(profile, count=BURST)
        shown = qos.describe(profile)
        keeps_all = profile.history == HistoryPolicy.KEEP_ALL
    if not got.matched:
        raise CheckFailed(f'Your subscription ({shown}) never matched the reliable, volatile '
                          f'publisher: {got.explanation or "they never matched."}')
    # The task says reliable; what a best-effort subscription keeps of a burst varies from run
    # to run, so its policy decides, as discovery reports it (the same in every run).
    if profile.reliability != ReliabilityPolicy.RELIABLE:
        raise CheckFailed(f'Your subscription is {qos.describe(profile)}: the display\'s '
                          'subscription is reliable, as the task says (the default): leave '
                          'reliability out, or give ReliabilityPolicy.RELIABLE.')
    if got.received == NEWEST:
        return (f'after a burst of {BURST}, a subscription with {shown} is left with '
                f'{NEWEST}: the newest reading only.')
    if keeps_all or (keeps_all is None and got.received == list(range(BURST))):
        raise CheckFailed(f'After a burst of {BURST} your subscription got all '
                          f'{len(got.received)}: KEEP_ALL (or a depth of {BURST} or more) keeps '
                          'every message; use KEEP_LAST with depth=1.')
    raise CheckFailed(f'After a burst of {BURST} your subscription got '
                      f'{len(got.received)} messages {_span(got.received)}: its history '
                      'keeps that many; a display of the newest reading keeps depth=1.')


@direct
def check_newest_only(judge: Optional[Judge], make_profile: Any) -> str:
    """Check part 1 of notebook 09: a subscription profile that keeps only the newest reading.

    A reliable publisher sends a burst of 30 numbers (0 to 29) before the subscription's
    callback runs once; a subscription with your profile must be left with ``[29]``.

    Introduced in ``09-qos.ipynb``.

    :param make_profile: your function returning the profile (no parentheses).
    :raises CheckFailed: naming what the subscription got instead.
    """
    return _newest_only(judge, make_profile)


def _latched(judge: Optional[Judge], make_profile: Any) -> str:
    if isinstance(make_profile, AnswerRef) and judge is not None:
        got, profile = _judged_late_joiner(judge, make_profile)
    else:
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
    if not got.received and profile.reliability != ReliabilityPolicy.RELIABLE:
        raise CheckFailed(f'{where} got none: a best-effort subscription is not sent what was '
                          'published before it joined: make it RELIABLE.')
    if not got.received:
        raise CheckFailed(f'{where} got none: the publisher kept nothing for it (a lifespan '
                          'lets old messages expire before anyone joins; leave it out).')
    if len(got.received) == LATCHED_SENT:
        raise CheckFailed(f'{where} got all {len(got.received)}: KEEP_ALL (or a depth of '
                          f'{LATCHED_SENT} or more) keeps every message; keep the last '
                          f'{LATCHED_KEPT} (KEEP_LAST, depth={LATCHED_KEPT}).')
    raise CheckFailed(f'{where} got {len(got.received)} {_span(got.received)}, expected the '
                      f'last {LATCHED_KEPT} {_span(LATCHED)}: depth={LATCHED_KEPT}.')


@direct
def check_latched_thresholds(judge: Optional[Judge], make_profile: Any) -> str:
    """Check part 3 of notebook 09: a "latched" profile that late joiners still hear.

    A publisher with your profile publishes 20 numbers with nobody listening; then a
    subscription with your profile joins.  It must get exactly the last five, 15 to 19.

    Introduced in ``09-qos.ipynb``.

    :param make_profile: your function returning the profile (no parentheses).
    :raises CheckFailed: naming what the late joiner got instead.
    """
    return _latched(judge, make_profile)


def _sensor_subscription(judge: Optional[Judge], make_profile: Any) -> str:
    if isinstance(make_profile, AnswerRef) and judge is not None:
        got, profile, history = _judged_match(judge, make_profile, SENSOR_QOS)
    else:
        profile = history = learner_profile(make_profile)
        got = qos.pair(SENSOR_QOS, profile, count=READINGS)
    sensor = qos.describe(SENSOR_QOS)
    if not got.matched:  # as discovery reports it, with the history it keeps: the same here
        raise CheckFailed(f'Incompatible QoS: the sensor publishes with {sensor}, your '
                          f'subscription asks for {qos.describe(profile, history)}; '
                          f'{got.explanation or "they never matched."}')
    # What it keeps when it falls behind: its history's alone.  A best-effort subscription
    # keeps what arrived, which varies from run to run; made reliable, it keeps the same.
    kept = _kept(history)
    if kept.received != SENSOR_KEPT:
        raise CheckFailed(f'After a burst of {BURST} while its callback was busy, your '
                          f'subscription kept {len(kept.received)} {_span(kept.received)}: '
                          f'the task keeps the last {len(SENSOR_KEPT)} readings '
                          f'{_span(SENSOR_KEPT)}: KEEP_LAST with depth={len(SENSOR_KEPT)}.')
    return (f'a subscription with {qos.describe(profile)} matches the sensor ({sensor}), no '
            f'incompatible-QoS event, and keeps the last {len(SENSOR_KEPT)} readings.')


def _reliable(profile: QoSProfile) -> QoSProfile:
    """``profile`` made reliable, its other policies kept."""
    made = copy.copy(profile)
    made.reliability = ReliabilityPolicy.RELIABLE
    return made


@direct
def check_sensor_subscription(judge: Optional[Judge], make_profile: Any) -> str:
    """Check part 2 of notebook 09: a subscription profile the best-effort sensor can serve.

    A publisher with rclpy's sensor-data preset (best effort, keep last 5, volatile) meets a
    subscription with your profile: rclpy's ``qos_check_compatible``, on both profiles as
    discovery reports them, must find nothing incompatible, and the two must match.  Then a
    burst of 30 (0 to 29) reaches a subscription with your profile's history while its
    callback is busy: it must keep the last five, 25 to 29.

    Introduced in ``09-qos.ipynb``.

    :param make_profile: your function returning the profile (no parentheses).
    :raises CheckFailed: with the one-line reason when the pair is incompatible, or naming
        what the subscription kept instead.
    """
    return _sensor_subscription(judge, make_profile)
