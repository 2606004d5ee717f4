"""A sample class for the grading test: one full solution, one partly solved, one per hostile case.

The samples are built from the current solutions/ and notebooks/ (so they never go stale),
with the change each case needs.  EXPECTED gives every learner's score per notebook (a
notebook not listed was not submitted and scores 0) and a phrase the feedback must show.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parent.parent
SOLUTION = {p.stem: p for p in (ROOT / 'solutions').glob('*.ipynb')}
LEARNER = {p.stem: p for p in (ROOT / 'notebooks').glob('*.ipynb')}
NB00, NB01, NB03, NB04 = (sorted(SOLUTION)[i] for i in (0, 1, 3, 4))

#: learner -> ({notebook: expected score}, {notebook: phrase in its feedback})
EXPECTED = {
    'full': ({n: s for n, s in zip(sorted(SOLUTION), (1, 1, 1, 3, 3, 5))}, {}),
    'partial': ({NB00: 0, NB01: 1, NB04: 2},
                {NB00: 'still raises NotImplementedError', NB04: 'still raises NotImplementedError'}),
    'hang-in-callback': ({NB00: 1}, {NB00: 'CellTimeoutError'}),
    'kills-kernel': ({NB00: 0}, {NB00: 'kernel died'}),
    'calls-rclpy-shutdown': ({NB00: 0}, {NB00: 'was rclpy.shutdown() called?'}),
    'prints-megabytes': ({NB00: 1}, {NB00: 'Check passed'}),
    'deletes-files': ({NB00: 0}, {NB00: 'it deleted the grading files around it'}),
    'wrong-topic': ({NB03: 1}, {NB03: 'needs a publisher on /temperature [std_msgs/msg/Float32]; '
                                      'it has: /temprature [std_msgs/msg/Float32]'}),
    'wrong-type': ({NB03: 1}, {NB03: 'needs a publisher on /temperature [std_msgs/msg/Float32]; '
                                     'it has: /temperature [std_msgs/msg/Float64]'}),
    'empty-file': ({NB00: 0}, {NB00: 'the file is empty'}),
    'corrupt-file': ({NB00: 0}, {NB00: 'not a valid notebook'}),
}


def _with_cell(source: Path, before_check: str) -> nbformat.NotebookNode:
    """The notebook with a code cell inserted just before its first learner-check cell."""
    nb = nbformat.read(source, as_version=4)
    index = next(i for i, c in enumerate(nb.cells) if 'learner-check' in c.metadata.get('tags', []))
    nb.cells.insert(index, nbformat.v4.new_code_cell(before_check))
    return nb


def _replaced(source: Path, old: str, new: str) -> nbformat.NotebookNode:
    nb = nbformat.read(source, as_version=4)
    hits = [c for c in nb.cells if old in c.source]
    assert hits, f'{old!r} not found in {source.name}'
    for cell in hits:
        cell.source = cell.source.replace(old, new)
    return nb


HANG_IN_CALLBACK = '''\
from rclpy.node import Node

class Stuck(Node):
    def __init__(self):
        super().__init__('stuck')
        self.create_timer(1.0, self.forever)

    def forever(self):
        while True:
            pass

ros2nb.add(Stuck())
ros2nb.spin(3)
'''

DELETES_FILES = '''\
import os, shutil
for target in ('.', '..', '../..', '../../..'):
    for entry in os.listdir(target):
        path = os.path.join(target, entry)
        shutil.rmtree(path, ignore_errors=True) if os.path.isdir(path) else os.remove(path)
'''


def build(folder: Path) -> Path:
    """Write the sample class into ``folder`` (one sub-folder per learner); return it."""
    def put(learner: str, notebook: str, nb) -> None:
        (folder / learner).mkdir(parents=True, exist_ok=True)
        target = folder / learner / f'{notebook}.ipynb'
        if isinstance(nb, Path):
            shutil.copy2(nb, target)
        elif isinstance(nb, str):
            target.write_text(nb)
        else:
            nbformat.write(nb, target)

    for notebook, path in SOLUTION.items():
        put('full', notebook, path)
    put('partial', NB00, LEARNER[NB00])
    put('partial', NB01, SOLUTION[NB01])
    put('partial', NB04, LEARNER[NB04])
    put('hang-in-callback', NB00, _with_cell(SOLUTION[NB00], HANG_IN_CALLBACK))
    put('kills-kernel', NB00, _with_cell(SOLUTION[NB00],
                                         'import os, signal\nos.kill(os.getpid(), signal.SIGKILL)'))
    put('calls-rclpy-shutdown', NB00, _with_cell(SOLUTION[NB00], 'import rclpy\nrclpy.shutdown()'))
    put('prints-megabytes', NB00, _with_cell(SOLUTION[NB00], "print('x' * 5_000_000)"))
    put('deletes-files', NB00, _with_cell(SOLUTION[NB00], DELETES_FILES))
    put('wrong-topic', NB03, _replaced(SOLUTION[NB03], "TOPIC = 'temperature'",
                                       "TOPIC = 'temprature'"))
    put('wrong-type', NB03, _replaced(SOLUTION[NB03], 'from std_msgs.msg import Float32',
                                      'from std_msgs.msg import Float64 as Float32'))
    put('empty-file', NB00, '')
    put('corrupt-file', NB00, '{"cells": [{"cell_type": "code", "sou')
    return folder
