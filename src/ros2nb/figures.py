"""The course's figures: the status palette, the bands and thresholds drawn with it, and the
one-line caption that says what a figure shows.

Introduced in ``04-write-the-subscriber.ipynb`` (the status bands); 03, 07 and 10 caption their
temperature plots with :func:`temperature_caption`, and ``ros2nb.graph_picture`` (06) captions
the ROS graph.  Every figure a notebook draws is followed by one line that starts with
:data:`CAPTION_START` and says, from the data, what the figure shows: a reader who cannot see
the picture (a screen reader, a text-only view of the notebook) reads it, and the course's
website makes it the picture's alternative text (docs/site/lessons.py).

The statuses are told apart by more than colour: each band has its colour from the Okabe–Ito
palette (chosen to stay apart in deuteranopia and protanopia: docs/decisions.md), a hatching
of its own and its name written on it.  No ROS import; nothing of matplotlib is imported here
(the functions that draw are handed the axes).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

from .course import HIGH_ABOVE_C, LOW_BELOW_C, MAX_TEMPERATURE_C, MIN_TEMPERATURE_C, STATUSES
from .nbmeta import CAPTION_START

#: The bands' opacity over the white axes: the line drawn over them stays dark on every band.
BAND_ALPHA = 0.3


@dataclass(frozen=True)
class StatusStyle:
    """How one status is drawn.

    :ivar colour: an Okabe–Ito colour (``#RRGGBB``).
    :ivar hatch: matplotlib's hatch pattern for its band (``''``: none).
    """

    colour: str
    hatch: str


#: Low blue, Normal bluish green, High orange (Okabe & Ito, "Color Universal Design", 2002).
STATUS_STYLES: dict[str, StatusStyle] = {
    'Low': StatusStyle('#0072B2', '\\\\'),
    'Normal': StatusStyle('#009E73', ''),
    'High': StatusStyle('#E69F00', '//'),
}
#: Each status's band, in °C: (lowest, highest).
STATUS_BANDS_C: dict[str, tuple[float, float]] = {
    'Low': (MIN_TEMPERATURE_C, LOW_BELOW_C),
    'Normal': (LOW_BELOW_C, HIGH_ABOVE_C),
    'High': (HIGH_ABOVE_C, MAX_TEMPERATURE_C),
}


def status_bands(ax: Any) -> None:
    """Draw the monitor's three status bands behind a temperature plot on ``ax`` (a matplotlib
    ``Axes`` whose y axis is in °C): each in its colour and hatching, with its name written at
    the band's right end and in the legend.

    Introduced in ``04-write-the-subscriber.ipynb``.
    """
    for status in STATUSES:
        low_c, high_c = STATUS_BANDS_C[status]
        style = STATUS_STYLES[status]
        ax.axhspan(low_c, high_c, facecolor=style.colour, alpha=BAND_ALPHA, hatch=style.hatch,
                   edgecolor='white', linewidth=0, label=status)
        ax.annotate(status, (0.995, (low_c + high_c) / 2), xycoords=('axes fraction', 'data'),
                    ha='right', va='center', fontsize=9, fontweight='bold',
                    bbox={'boxstyle': 'round,pad=0.2', 'facecolor': 'white',
                          'edgecolor': style.colour, 'alpha': 0.9})


def threshold_lines(ax: Any) -> None:
    """Draw the monitor's two thresholds on ``ax`` as dashed lines, each named on the plot
    (``High above 26 °C``, ``Low below 20 °C``), in its status's colour.

    Introduced in ``07-live-plot.ipynb`` (and used in ``10-record-and-replay.ipynb``).
    """
    for status, threshold_c, words in (('High', HIGH_ABOVE_C, 'High above'),
                                       ('Low', LOW_BELOW_C, 'Low below')):
        ax.axhline(threshold_c, color=STATUS_STYLES[status].colour, linestyle='--', linewidth=1.2)
        ax.annotate(f'{words} {threshold_c:g} °C', (0.01, threshold_c),
                    xycoords=('axes fraction', 'data'), xytext=(0, 3), textcoords='offset points',
                    fontsize=8)


def _span(seconds: float) -> str:
    return f'{seconds:.0f} s' if seconds < 120 else f'{seconds / 60:.1f} min'


def temperature_caption(what: str, times_s: Sequence[float], temps_c: Sequence[float]) -> str:
    """The caption line of a temperature plot, from its data: how many readings over how long,
    their range, and how many the monitor would call Low, Normal and High.

    ``temperature_caption('Temperature over one simulated hour', times_s, temps_c)`` gives
    ``'Figure: Temperature over one simulated hour: 3600 readings over 60.0 min, 18.0–26.4 °C;
    Low 412, Normal 3105, High 83 (Low below 20 °C, High above 26 °C).'``

    Introduced in ``03-write-the-publisher.ipynb``.

    :param what: what the figure shows, in a few words (its title, say).
    :param times_s: when each reading was taken (s), as plotted.
    :param temps_c: the readings (°C), as many as ``times_s``.
    :raises ValueError: when the two lists differ in length.
    """
    if len(times_s) != len(temps_c):
        raise ValueError(f'temperature_caption() got {len(times_s)} times and {len(temps_c)} '
                         'readings: give it the two lists the plot draws, one time per reading.')
    if not temps_c:
        return f'{CAPTION_START}{what}: no readings yet; the plot fills as they arrive.'
    # The monitor's rule is an answer: imported here, never by a process that only imports
    # this module for its palette (a judge's subject refuses it: ros2nb.subject.out_of_reach).
    from .rules import monitor_status
    counts = {status: 0 for status in STATUSES}
    for temp_c in temps_c:
        counts[monitor_status(temp_c)] += 1
    readings = f'{len(temps_c)} reading{"s" if len(temps_c) != 1 else ""}'
    if len(temps_c) > 1:
        readings += f' over {_span(max(times_s) - min(times_s))}'
    line = f'{CAPTION_START}{what}: {readings}, {min(temps_c):.1f}–{max(temps_c):.1f} °C'
    if counts['Normal'] == len(temps_c):
        return f'{line}, all inside the Normal band ({LOW_BELOW_C:g}–{HIGH_ABOVE_C:g} °C).'
    shares = ', '.join(f'{status} {counts[status]}' for status in STATUSES)
    return (f'{line}; {shares} (Low below {LOW_BELOW_C:g} °C, '
            f'High above {HIGH_ABOVE_C:g} °C).')
