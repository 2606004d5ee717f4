"""One line for each beginner mistake, naming the learner's own line and the fix.

Runs wherever the learner's code runs through ros2nb: their kernel, and a check's subject.
``exceptions`` explains an error rclpy or a message raised, asking ``settings`` (QoS,
parameters, ``-r``/``-p`` rules), ``plain_python`` (Python used as another tool is),
``bag_reading`` (rosbags) and ``plots`` (pyplot in a callback); ``blocking`` refuses
``time.sleep`` in a callback of a check's subject; ``everyday`` Python's own errors (with
``names`` and ``values``); ``frames`` tells the
learner's frames from the libraries'; ``guards`` refuses a node or an endpoint with a mistake
before it runs.  This ``__init__`` imports nothing.
"""
