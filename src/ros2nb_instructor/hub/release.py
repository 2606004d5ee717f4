"""``ros2nb-hub-feedback``: give each learner on the hub their own feedback pages.

Runs on the classroom server (``make hub-feedback GRADING=grading``), as root, after
``make grade``.  Each learner's pages, ``grading/feedback/<learner>/<NN-title>.html``, go into
the hub's hand-in store (:mod:`.hand_in_store`), where the hand-in service shows each learner
their own at ``/services/hand-in/feedback/`` and nobody else's (``ros2nb.progress()`` links
them).  Releasing again replaces a learner's pages with the newer grading's.  A folder whose
name is not a hub user name the store keeps is named and skipped.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Optional

from ..paths import ROOT
from .collect import DEFAULT_STORE
from .hand_in_store import Refused, Store


def release(grading: Path, store: Store) -> list[str]:
    """Release every learner's pages of ``grading`` into ``store``; one line per learner."""
    lines = []
    folders = sorted((grading / 'feedback').iterdir()) if (grading / 'feedback').is_dir() else []
    for folder in folders:
        if folder.is_symlink() or not folder.is_dir():
            continue
        pages = sorted(p for p in folder.glob('*.html')
                       if p.stem in store.notebooks and not p.is_symlink())
        try:
            for page in pages:
                store.release(folder.name, page.stem, page.read_bytes())
        except Refused as why:
            lines.append(f'{folder.name}: not released ({why})')
            continue
        lines.append(f'{folder.name}: {len(pages)} page(s) released')
    return lines


def main(argv: Optional[list[str]] = None) -> int:
    """Release a grading's feedback to the hub's learners; 0 when it worked."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('grading', type=Path, nargs='?', default=ROOT / 'grading')
    parser.add_argument('--store', type=Path,
                        default=Path(os.environ.get('ROS2_COURSE_HUB_HANDED_IN', DEFAULT_STORE)))
    args = parser.parse_args(argv)
    if not (args.grading / 'feedback').is_dir():
        print(f'{args.grading} holds no feedback: run make grade first (GRADING=folder names '
              'another grading)')
        return 2
    for line in release(args.grading, Store(args.store)):
        print(line)
    return 0


if __name__ == '__main__':
    sys.exit(main())
