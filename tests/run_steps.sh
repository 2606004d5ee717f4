#!/usr/bin/env bash
# `make test`: the four test steps, every time, then their results together.
#
#   1. the slow lane of tests/ with pytest-xdist (in the foreground: its output is what you
#      watch; `make check` ran the fast lane before), but the image;
#   2. nbval over solutions/ (every deterministic output compared);
#   3. nbval over notebooks/ (every check of an unwritten part must fail with its message);
#   4. the course's image, built and run with podman (tests/test_image.py: a newcomer's first
#      run builds it cold, minutes of mostly downloads and compiling).
#
# Steps 2 to 4 run alongside step 1, each in its own pytest process (every process and
# kernel claims a ROS domain and a workspace of its own); their output is kept in a log
# and shown once step 1 has ended.  One failure never hides another: the exit code is 1
# if any step failed.  A step still running after STEP_LIMIT_S seconds (a hang that every
# per-test limit missed) is stopped and says so: make test always ends with its results.
# Each result gives the step's wall seconds and the CPU seconds of all its processes
# (tests/run_counted.py).  What ended processes left behind (temporary folders, sandbox
# cgroups) is swept first and last (tests/left_behind.py); processes a step left running
# are ended by its run_counted.py.
#
# Every step runs at the same priority (NBVAL_NICE=0).  The sample class (step 1's longest
# chain) is scored as each learner ends, so tests/ is CPU-bound across all its workers, not
# held up by one chain: a lower priority for steps 2 and 3 would not let the class go first,
# it would only give other programs on the machine a larger share of the two cores (at nice 5
# a step weighs a third of a CPU burner at nice 0).
# Usage: tests/run_steps.sh PYTHON WORKERS
set -u
python=$1 workers=$2
STEP_LIMIT_S=${STEP_LIMIT_S:-3000}
NBVAL_NICE=${NBVAL_NICE:-0}
"$python" tests/left_behind.py  # what an earlier run, killed, left
logs=$(mktemp -d "${TMPDIR:-/tmp}/ros2nb-make-test-$$-XXXXXX")  # named for this shell: swept
trap 'rm -rf "$logs"' EXIT

run() {  # run NAME NICENESS ARGS...: pytest ARGS; its exit code to $logs/NAME.rc, its wall
         # seconds to $logs/NAME.s, the CPU seconds of all its processes to $logs/NAME.cpu
    local name=$1 niceness=$2 began=$SECONDS
    shift 2
    # --foreground: Ctrl+C at the terminal still reaches pytest; SIGINT lets it say where it was.
    "$python" tests/run_counted.py "$logs/$name.cpu" \
        timeout --foreground --signal=INT --kill-after=60 "$STEP_LIMIT_S" \
        nice -n "$niceness" "$python" -m pytest "$@"
    local rc=$?
    if [ $((SECONDS - began)) -ge "$STEP_LIMIT_S" ]; then
        echo "=== make test: $name was still running after $STEP_LIMIT_S s and was stopped" \
             "(a hang no test limit caught: its output above ends where it hung)"
    fi
    echo "$rc" > "$logs/$name.rc"
    echo $((SECONDS - began)) > "$logs/$name.s"
}

# Fast DDS's own cleaner of the shared-memory files that ROS processes killed earlier left in
# /dev/shm (files of live processes stay): on such a stale port, participants of the next runs
# took seconds more to discover each other, and a check that waits for a node could time out.
"$(dirname "$python")/fastdds" shm clean > /dev/null 2>&1 || echo "=== make test: fastdds shm clean failed (going on)"

run solutions "$NBVAL_NICE" --nbval solutions --nbval-current-env --nbval-sanitize-with tests/sanitize.cfg \
    > "$logs/solutions.log" 2>&1 &
run notebooks "$NBVAL_NICE" --nbval-lax notebooks --nbval-current-env > "$logs/notebooks.log" 2>&1 &
run image "$NBVAL_NICE" tests/test_image.py --lane slow -q > "$logs/image.log" 2>&1 &
echo "=== make test: the slow lane of tests/ (nbval over solutions/ and notebooks/, and the" \
     "image, run alongside)"
run tests 0 tests --lane slow -m 'not image' -n "$workers" --dist loadfile --no-loadscope-reorder \
    --durations=15
wait
for name in solutions notebooks image; do
    echo "=== make test: $([ "$name" = image ] && echo "the image" || echo "nbval $name/") (ran alongside tests/)"
    cat "$logs/$name.log"
done
"$python" tests/left_behind.py  # what the steps' ended processes left
failed=0
echo "=== make test: results"
for name in tests solutions notebooks image; do
    rc=$(cat "$logs/$name.rc" 2>/dev/null || echo 'none')
    case $name in tests) label='tests/' ;; image) label='the image' ;; *) label="nbval $name/" ;; esac
    if [ "$rc" = 0 ]; then result=passed; else result="FAILED (exit $rc)"; failed=1; fi
    printf '  %-17s %s in %s s (%s CPU-s)\n' "$label" "$result" \
        "$(cat "$logs/$name.s" 2>/dev/null || echo '?')" "$(cat "$logs/$name.cpu" 2>/dev/null || echo '?')"
done
exit $failed
