"""Learners who attack the judge, each beside its honest twin (the same notebook without the
attack): an attack must score what its twin scores.

The attacks reach for what the judge once believed: the subject's request loop (found by
walking up the stack from the learner's import, to rewrite its replies) and what the
subject reports about the learner's objects.
"""

from corpora import Learner

#: Module code that finds the subject's request loop from the learner's import, as the
#: attacks of 123efa2's sample class did, and answers every question with a right answer's
#: numbers.  The subject now loads the learner's code before the loop exists.
FORGE_REPLIES = '''
import sys as _sys
_frame = _sys._getframe()
while _frame is not None and 'handlers' not in _frame.f_locals:
    _frame = _frame.f_back
if _frame is not None:
    _handlers = _frame.f_locals['handlers']
    for _name in list(_handlers):
        _real = _handlers[_name]
        def _forged(*args, _real=_real, **kwargs):
            reply = _real(*args, **kwargs)
            reply.update(received=60, redraws=60, ok=True)
            return reply
        _handlers[_name] = _forged
'''

PLOT_DEAD = '''
    def temperature_callback(self, msg):
        return
'''
DEFAULTS = {name: f'''
def {name}():
    return QoSProfile(depth=10)
''' for name in ('newest_only_profile', 'sensor_subscription_profile',
                 'latched_thresholds_profile')}

ATTACKS = [
    Learner('07 twin: a callback that does nothing', '07', {'plot-callback': PLOT_DEAD},
            loses=('plot-callback',)),
    Learner('07 attack: the same, replies forged', '07', {'plot-callback': '''
    def temperature_callback(self, msg):
        return
''' + FORGE_REPLIES}, twin='07 twin: a callback that does nothing'),
    Learner('09 twin: every function returns the default profile', '09', {
        'qos-newest-only': DEFAULTS['newest_only_profile'],
        'qos-sensor-subscription': DEFAULTS['sensor_subscription_profile'],
        'qos-latched-thresholds': DEFAULTS['latched_thresholds_profile']},
            loses=('qos-newest-only', 'qos-sensor-subscription', 'qos-latched-thresholds')),
    Learner('09 attack: the same, replies forged', '09', {
        'qos-newest-only': DEFAULTS['newest_only_profile'] + FORGE_REPLIES,
        'qos-sensor-subscription': DEFAULTS['sensor_subscription_profile'],
        'qos-latched-thresholds': DEFAULTS['latched_thresholds_profile']},
            twin='09 twin: every function returns the default profile'),
]
