"""``plt.pause()`` and ``plt.show()`` refused inside a node's callback, and ``plt.show()`` of
a figure the cell already showed, with one line.

Part of :mod:`ros2nb.explain`; installed by :func:`ros2nb.start` in a kernel and in every
judge's subject.  Called from a callback, ``plt.pause`` holds the executor up for its
interval on every message (notebook 07's live cell then takes a minute instead of a
second) and, like ``plt.show``, draws another copy of the figure under the cell each time;
the live plot's ``redraw()`` already asks for a redraw without waiting.  Outside callbacks
both work as matplotlib's own.  Introduced in ``07-live-plot.ipynb``.
"""

from __future__ import annotations

import importlib.abc
import importlib.util
import sys
from typing import Any, Optional

from ..errors import Ros2nbError
from .frames import in_callback

PYPLOT = 'matplotlib.pyplot'
_GUARDED = '_ros2nb_guarded'
_WHY = {'pause': 'waits its interval on every message, holding up every other callback',
        'show': 'draws the whole figure again on every message (in a notebook, one more copy '
                'under the cell each time)'}


class PlotInCallbackError(Ros2nbError):
    """``plt.pause()`` or ``plt.show()`` was called inside a node's callback."""


class FigureShownAgainError(Ros2nbError):
    """``plt.show()`` was called again for a figure the same cell already showed."""


def plot_in_callback(exc: BaseException, text: str) -> Optional[str]:
    """The line of a :class:`PlotInCallbackError` or :class:`FigureShownAgainError` (its own
    message), or None."""
    return text if isinstance(exc, (PlotInCallbackError, FigureShownAgainError)) else None


#: The figure manager each cell showed last: (its id, the cell's execution count).
_shown: list[tuple[int, int]] = []


def _shown_again(pyplot: Any) -> Optional[str]:
    """The line for ``plt.show()`` of a figure this cell already showed (in a loop, say), or
    None.  In a notebook each call draws one more copy of it under the cell (a widget
    backend's ``show`` displays the canvas again); a loop wants one figure, updated."""
    shell = getattr(sys.modules.get('IPython'), 'get_ipython', lambda: None)()
    manager = pyplot.get_current_fig_manager() if pyplot.get_fignums() else None
    if shell is None or manager is None:
        return None
    shown = (id(manager), shell.execution_count)
    if shown in _shown:
        return ('plt.show() showed this figure again in the same cell, and each call puts one '
                'more copy of it under the cell: keep one figure and update it: show it once, '
                'before the loop, and in the loop change its data (line.set_data(...)) and call '
                'fig.canvas.draw_idle().')
    _shown[:] = [shown]
    return None


def _guard(pyplot: Any) -> None:
    for name in ('pause', 'show'):
        original = getattr(pyplot, name)
        if getattr(original, _GUARDED, False):
            continue

        def guarded(*args: Any, _original: Any = original, _name: str = name, **kwargs: Any) -> Any:
            if in_callback(sys._getframe(1)):
                raise PlotInCallbackError(
                    f'plt.{_name}() in a callback {_WHY[_name]}: remove it; redraw() already '
                    'asks for a redraw without waiting (the plot updates between messages).')
            again = _shown_again(pyplot) if _name == 'show' else None
            if again:
                raise FigureShownAgainError(again)
            return _original(*args, **kwargs)

        guarded.__doc__, guarded.__name__ = original.__doc__, name
        setattr(guarded, _GUARDED, True)
        setattr(pyplot, name, guarded)


class _GuardOnImport(importlib.abc.MetaPathFinder):
    """Guards ``matplotlib.pyplot`` as it is imported (a learner's file imports it late)."""

    def find_spec(self, name: str, path: Any, target: Any = None) -> Optional[Any]:
        if name != PYPLOT:
            return None
        sys.meta_path.remove(self)  # find it as if this finder were not there
        try:
            spec = importlib.util.find_spec(name)
        finally:
            sys.meta_path.insert(0, self)
        if spec is None or spec.loader is None:
            return spec
        execute = spec.loader.exec_module

        def exec_module(module: Any) -> None:
            execute(module)
            _guard(module)

        spec.loader.exec_module = exec_module  # type: ignore[method-assign]  # then the guard
        return spec


def guard_pyplot() -> None:
    """Make ``plt.pause``/``plt.show`` refuse, with one line, to run in a node's callback:
    pyplot now if it is imported, else as soon as it is.  Installing it again changes nothing.

    Introduced in ``07-live-plot.ipynb`` (installed by :func:`ros2nb.start`).
    """
    if PYPLOT in sys.modules:
        _guard(sys.modules[PYPLOT])
    elif not any(isinstance(finder, _GuardOnImport) for finder in sys.meta_path):
        sys.meta_path.insert(0, _GuardOnImport())
