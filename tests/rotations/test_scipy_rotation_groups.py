"""scipy's own test_rotation_groups.py (create_group, reduce), read from the installed scipy, run against Attitude."""

from scipy_adapter import load

EXPECTED_FAILURES: dict[str, str] = {}

load("test_rotation_groups", globals(), EXPECTED_FAILURES)
