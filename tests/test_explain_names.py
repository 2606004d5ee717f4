"""A name a function reads that nothing set: the line says where it was set under another
spelling, or which name was meant, and never suggests the learner's own slip back, a name
IPython keeps for itself, or a builtin the learner never meant.

Each case is a learner's module (a node file, or a cell's code) that the check loads; the
comment beside it is the line the course said before, the failure it prevents.
"""

import importlib.util
import sys
from types import SimpleNamespace

import pytest

from ros2nb.explain.everyday import everyday_explanation
from ros2nb.explain.names import builtin_meant, similar

#: The top of a node file as the course gives it: its constants, named in its comments.
TOP = '''import random

TOPIC = 'temperature'
QUEUE_DEPTH = 10              # messages kept for a slow subscription
'''


def _told(tmp_path, source: str, call: str, *args: object) -> str:
    path = tmp_path / 'temperature_monitor.py'
    path.write_text(source)
    spec = importlib.util.spec_from_file_location('temperature_monitor', path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    with pytest.raises(NameError) as caught:
        getattr(module, call)(*args)
    return everyday_explanation(caught.value)


def test_a_top_level_name_set_misspelt_is_placed_not_suggested_back(tmp_path):
    """TOPIC set as TOIC, read as TOPIC in a function: before, "did you mean TOIC?", the
    learner's own slip suggested back and the line that set it never named."""
    source = TOP.replace("TOPIC = 'temperature'", "TOIC = 'temperature'") + '''

def subscribe():
    # a subscription to Float32 messages on TOPIC, QUEUE_DEPTH deep
    return TOPIC, QUEUE_DEPTH
'''
    told = _told(tmp_path, source, 'subscribe')
    assert told == ("name 'TOPIC' is not defined, but TOIC is (temperature_monitor.py line 3: "
                    "TOIC = 'temperature'): spell a name the same where it is set and where it "
                    'is used.')
    assert 'did you mean TOIC' not in told


def test_a_use_misspelt_is_told_the_name_the_file_sets(tmp_path):
    """TOPIC read as TOIC: the name the file sets, and spells everywhere else, is meant."""
    source = TOP + '''

def subscribe():
    # a subscription to Float32 messages on TOPIC, QUEUE_DEPTH deep
    return TOIC, QUEUE_DEPTH
'''
    assert _told(tmp_path, source, 'subscribe') == (
        "name 'TOIC' is not defined: did you mean TOPIC? Names must match exactly.")


def test_an_import_under_another_name_is_placed(tmp_path):
    """``import ... as EET``, then ET in the function: before, "did you mean EET?"."""
    source = '''import xml.etree.ElementTree as EET


def package_dependencies(package_xml='package.xml'):
    return ET.parse(package_xml).getroot()
'''
    assert _told(tmp_path, source, 'package_dependencies') == (
        "name 'ET' is not defined, but EET is (temperature_monitor.py line 1: import "
        'xml.etree.ElementTree as EET): spell a name the same where it is set and where it is '
        'used.')


def test_no_builtin_is_offered_where_none_was_meant(tmp_path):
    """``def main():`` without its ``args=None``: before, "did you mean vars?"."""
    source = TOP + '''

def main():
    return dict(args=args)
'''
    assert _told(tmp_path, source, 'main') == (
        "name 'args' is not defined where this line runs: no line before it sets args: set it "
        'first, or check its spelling.')


@pytest.mark.parametrize('name, meant', [
    ('KeyboardIntrrupt', 'KeyboardInterrupt'),  # one letter left out
    ('supr', 'super'),
    ('ags', None),     # before: abs, as near to ags as the args meant
    ('args', None),    # before: vars
    ('lne', None),     # as near to len as to anything three letters long
])
def test_a_builtin_is_offered_only_for_a_slip_of_it(name, meant):
    assert builtin_meant(name) == meant


def test_the_kernels_own_names_are_never_offered(monkeypatch):
    """In a kernel IPython keeps Out, exit and _i3 among the learner's names, and the
    grader's run of the same cell has none: before, "did you mean Out?" in the lab only."""
    hidden = {'Out': {}, 'exit': None, '_i3': ''}
    shell = SimpleNamespace(user_ns_hidden=hidden)
    monkeypatch.setitem(sys.modules, 'IPython', SimpleNamespace(get_ipython=lambda: shell))
    names = {*hidden, 'RUN_S', 'Talker'}
    assert similar('Ot', names) is None
    assert similar('exi', names) is None
    assert similar('_i', names) is None
    assert similar('RUN_', names) == 'RUN_S'


def test_a_parameter_named_otherwise_is_named(tmp_path):
    """``def package_dependencies(xml)``, its body reading package_xml: before, "no line
    before it sets package_xml", never the parameter the learner renamed."""
    source = '''import xml.etree.ElementTree as ET


def package_dependencies(xml):
    root = ET.parse(package_xml).getroot()
    return [element.text for element in root.findall('depend')]
'''
    assert _told(tmp_path, source, 'package_dependencies', 'package.xml') == (
        "name 'package_xml' is not defined: package_dependencies calls its parameter xml, "
        'which it never reads (temperature_monitor.py line 4: def package_dependencies(xml):): '
        'name the parameter package_xml, or read xml.')


def test_a_parameter_misspelt_is_named_not_suggested_back(tmp_path):
    """``def main(ags=None)``, then ``args``: "did you mean ags?" would suggest the slip."""
    source = TOP + '''

def main(ags=None):
    return dict(args=args)
'''
    assert _told(tmp_path, source, 'main') == (
        "name 'args' is not defined: main calls its parameter ags, which it never reads "
        '(temperature_monitor.py line 7: def main(ags=None):): name the parameter args, or read '
        'ags.')


def test_a_parameter_the_function_ignores_is_no_other_names(tmp_path):
    """A callback that never reads its msg, and a module it never imported: the import."""
    source = '''def count(msg):
    return random.random()
'''
    told = _told(tmp_path, source, 'count', 1.0)
    assert told == "name 'random' is not defined: import it at the top of the file (or cell), " \
        'import random.'


def test_a_use_of_a_parameter_misspelt_is_told_the_parameter(tmp_path):
    """06's mutant ``rclpy.init(args=ags)`` in ``def main(args=None)``: the use slipped, and
    the parameter is what is meant, never "name the parameter ags"."""
    source = TOP + '''

def main(args=None):
    return dict(args=ags)
'''
    assert _told(tmp_path, source, 'main') == (
        "name 'ags' is not defined: did you mean args? Names must match exactly.")
