"""The tutorial's terminal, from a notebook: one module per group of commands it types.

Runs in the learner's kernel.  ``workspace`` (``mkdir -p``, ``tree``), ``files`` (the files
the learner writes, ``%%part``), ``colcon`` (``colcon build``, ``source``), ``pkg_create``
(``ros2 pkg create``), ``run`` (``ros2 run`` and Ctrl+C), ``topic`` and ``echo`` (``ros2
node``/``ros2 topic``), ``param`` (``ros2 param``).  The real command is used wherever it exists
(colcon always; ``ros2`` when it is on PATH); elsewhere these print what it prints.  This
``__init__`` imports nothing of ROS, so that ``ros2nb.course`` can use the file verbs without it.
"""


from ..on_first_use import loader

#: ``ros2nb.terminal.bag`` (notebook 10) loads on first use, with rosbags.
__getattr__, __dir__ = loader(globals(), {'bag': 'bag'})
