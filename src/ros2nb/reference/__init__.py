"""Reference sources of the course (the tutorial code with its mistakes fixed)."""
