"""A subject: the process in which the judge runs the learner's code, and trusts nothing it says.

Runs the learner's code (their file imported, their answer cells executed, their node on
simulated time in a runtime of its own) for the judge, which sends one JSON command at a
time and reads one JSON reply of raw facts.  Whether those facts are right is decided in
the judge, which also watches the node over ROS itself; anything that runs in a process
with learner code is the learner's to forge, so no verdict comes from here.  While
grading, it runs in a sandbox of its own.  This ``__init__`` imports nothing.
"""
