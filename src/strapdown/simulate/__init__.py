"""Motion and IMU simulation with exact truth (filled in by the modules of this package)."""
