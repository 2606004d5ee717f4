"""QoS profiles in words: one line for a profile, why two cannot talk, and an endpoint as
``ros2 topic info --verbose`` prints it.

Introduced in ``09-qos.ipynb`` (through :mod:`ros2nb.qos`, which runs the trials).  Whether
two profiles can talk is rclpy's to say (``qos_check_compatible``, which knows every DDS
rule); this module only words its answer and says what to change.
"""

from __future__ import annotations

from typing import Any, Optional

from rclpy.qos import (HistoryPolicy, QoSCompatibility, QoSPolicyKind, QoSProfile,
                       qos_check_compatible)


def describe(profile: QoSProfile, kept: Optional[QoSProfile] = None) -> str:
    """One line: ``RELIABLE, KEEP_LAST (10), VOLATILE``; with ``kept``, its history and depth
    (discovery carries neither: a subject says what its profile keeps)."""
    history = kept if kept is not None else profile
    if history.history not in (HistoryPolicy.KEEP_LAST, HistoryPolicy.KEEP_ALL):
        return f'{profile.reliability.name}, {profile.durability.name}'  # as discovered
    depth = f' ({history.depth})' if history.history == HistoryPolicy.KEEP_LAST else ''
    return f'{profile.reliability.name}, {history.history.name}{depth}, {profile.durability.name}'


#: What to change for each kind of incompatibility rclpy names (a word of its reason).
_ADVICE = (('reliab', 'a best-effort publisher never resends, so it cannot serve a '
                      'reliable subscription; make the subscription BEST_EFFORT (or '
                      'the publisher RELIABLE)'),
           ('durab', 'a volatile publisher keeps nothing for late joiners; make the subscription '
                     'VOLATILE (or the publisher TRANSIENT_LOCAL)'),
           ('deadline', 'a subscription may only ask for a deadline the publisher promises; '
                        'leave the deadline out of the subscription\'s profile'),
           ('lease', 'a subscription may only ask for a liveliness lease the publisher '
                     'promises; leave the lease duration out of the subscription\'s profile'),
           ('liveliness', 'a subscription may only ask for the liveliness the publisher '
                          'offers; leave liveliness at its default (AUTOMATIC)'))


def incompatibility(offered: QoSProfile, requested: QoSProfile) -> Optional[str]:
    """Explain in one line why a publisher's profile cannot serve a subscription's, or None.

    rclpy's own ``qos_check_compatible`` decides (every DDS rule: reliability, durability,
    deadline, liveliness and its lease); its reason comes first, then what to change.  A
    pair it only warns about (a policy left to the system default) is None: whether it
    matches is then the middleware's to show.
    """
    compatibility, reason = qos_check_compatible(offered, requested)
    if compatibility != QoSCompatibility.ERROR:
        return None
    said = reason.strip().rstrip(';').removeprefix('ERROR:').strip()
    advice = next((text for word, text in _ADVICE if word in said.lower()),
                  'make the subscription ask for no more than the publisher offers')
    return f'rclpy says: {said}; {advice}.'


def endpoint_lines(info: Any) -> list[str]:
    """An endpoint's block of ``ros2 topic info --verbose``: node, type, QoS profile."""
    qos = info.qos_profile
    history = _policy(qos.history)
    return [f'Node name: {info.node_name}', f'Node namespace: {info.node_namespace}',
            f'Topic type: {info.topic_type}', f'Endpoint type: {_policy(info.endpoint_type)}',
            'QoS profile:', f'  Reliability: {_policy(qos.reliability)}',
            f'  History (Depth): {history}' if history == 'UNKNOWN' else
            f'  History (Depth): {history} ({qos.depth})',
            f'  Durability: {_policy(qos.durability)}', f'  Lifespan: {_duration(qos.lifespan)}',
            f'  Deadline: {_duration(qos.deadline)}', f'  Liveliness: {_policy(qos.liveliness)}',
            f'  Liveliness lease duration: {_duration(qos.liveliness_lease_duration)}']


def _policy(value: Any) -> str:
    return value.name if hasattr(value, 'name') else str(value)


def _duration(value: Any) -> str:
    nanoseconds = value.nanoseconds if hasattr(value, 'nanoseconds') else int(value)
    # rmw reports "infinite" as the largest representable duration.
    return 'Infinite' if nanoseconds >= 0x7FFFFFFFFFFFFFFF or nanoseconds == 0 else \
        f'{nanoseconds} nanoseconds'


def policy_name(kind: Any) -> str:
    """``QoSPolicyKind.RELIABILITY`` (or its number) -> ``'Reliability'``."""
    try:
        return QoSPolicyKind(kind).name.capitalize()
    except ValueError:
        return str(kind)


def why_unmatched(node: Any, topic: str, ours: str) -> Optional[str]:
    """Why an endpoint of the nodes named ``ours...`` (a prefix) on ``topic`` and another's
    cannot talk, from the profiles the graph shows (``node`` sees it): ``'publisher'`` or
    ``'subscription'`` (the one of ours it cannot reach), then :func:`incompatibility`'s line;
    None when every pair could match."""
    publishers = node.get_publishers_info_by_topic(topic)
    subscriptions = node.get_subscriptions_info_by_topic(topic)
    for offers, requests, side in ((publishers, subscriptions, 'subscription'),
                                   (publishers, subscriptions, 'publisher')):
        for offered in offers:
            for requested in requests:
                mine = offered if side == 'publisher' else requested
                other = requested if side == 'publisher' else offered
                if not mine.node_name.startswith(ours) or other.node_name.startswith(ours):
                    continue
                why = incompatibility(offered.qos_profile, requested.qos_profile)
                if why:
                    return f'{side}: {why}'
    return None
