#!/usr/bin/env python3
"""What a flooder costs a class: two complete learners graded alone, then beside a learner
whose sensor floods /rosout.

``python benchmarks/flood_class.py [--reps N] [--kind rosout|topic|callback]`` grades, with
``ros2nb-grade`` in its sandboxes, a class of two learners who handed in every notebook
complete, and the same class with a third who handed in only notebook 03, written as the
solution but with a constructor that starts a thread logging as fast as it can (``--kind
topic``: publishing on /temperature as fast as it can; ``--kind callback``: no thread, a
callback that logs 450 lines a reading, a slow flood under the judge's flood limit;
``tests/test_floods.py`` has all three).  The two classes are
graded in turn, ``--reps`` times (default 1).  It prints, per grading, the wall seconds and
the CPU seconds of ``ros2nb-grade`` and every process it started (read from ``/proc`` every
50 ms, by parent: other work on the machine is left out), the flooder's score of 03 and the
line of its failed part; then the ratio of the class with the flooder to the two alone (the
issue's target: at most 1.5).  Needs what grading needs (root and bubblewrap); Linux only.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

from ros2nb.temporary import temporary_folder

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / 'tests'))
from sampling import TreeCpu  # noqa: E402
from test_floods import flooder_notebook  # noqa: E402

GRADE = str(Path(sys.executable).with_name('ros2nb-grade'))
def grade(folder: Path, out: Path) -> tuple[float, float]:
    """Grade ``folder``'s learners: wall seconds and CPU seconds of the grading's processes."""
    started = time.monotonic()
    proc = subprocess.Popen([GRADE, str(folder), '--out', str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    with TreeCpu(proc.pid) as cpu:
        output, _ = proc.communicate()
    if proc.returncode != 0:
        sys.exit(f'ros2nb-grade exited {proc.returncode}: {output[-800:]}')
    return time.monotonic() - started, sum(cpu.seen.values())


def flooder_result(out: Path) -> str:
    """The flooder's score of 03 and the lines of its failed checks, from its feedback page."""
    import html
    import re
    found = [row for row in (out / 'grades.csv').read_text().splitlines()
             if row.startswith('flooder,03')]
    for page in (out / 'feedback' / 'flooder').rglob('03*.html'):
        text = html.unescape(re.sub(r'<[^>]+>', ' ', page.read_text()))
        found += sorted({m.strip() for m in re.findall(
            r'(?:CheckFailed|LearnerCodeError|Your node|Your code|checking it reached)'
            r'[^\n]{0,300}',
            text)})
    return '\n'.join(found)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--reps', type=int, default=1)
    parser.add_argument('--kind', choices=('rosout', 'topic', 'callback'), default='rosout',
                        help='what the flooder floods (default: /rosout from a thread)')
    options = parser.parse_args()
    kind = options.kind
    solutions = sorted((ROOT / 'solutions').glob('*.ipynb'))
    measured: dict[str, list[tuple[float, float]]] = {'two alone': [], 'with flooder': []}
    with temporary_folder('flood') as tmp:
        for rep in range(options.reps):
            for label in measured:
                root = Path(tmp) / f'{rep}-{label.replace(" ", "-")}'
                for name in ('learner1', 'learner2'):
                    (root / 'class' / name).mkdir(parents=True)
                    for notebook in solutions:
                        shutil.copy2(notebook, root / 'class' / name / notebook.name)
                if label == 'with flooder':
                    (root / 'class' / 'flooder').mkdir()
                    target = root / 'class' / 'flooder' / next(
                        n.name for n in solutions if n.name.startswith('03'))
                    target.write_text(json.dumps(flooder_notebook(kind)))
                wall, cpu = grade(root / 'class', root / 'grading')
                measured[label].append((wall, cpu))
                print(f'| {rep + 1} | {label} | {wall:.0f} | {cpu:.0f} |', flush=True)
                if label == 'with flooder':
                    print(flooder_result(root / 'grading'), flush=True)
    alone = statistics.median(c for _w, c in measured['two alone'])
    flooded = statistics.median(c for _w, c in measured['with flooder'])
    walls = [statistics.median(w for w, _c in measured[k]) for k in measured]
    print(f'CPU-s ratio with the flooder / two alone: {flooded / alone:.2f} '
          f'(wall {walls[1] / walls[0]:.2f})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
