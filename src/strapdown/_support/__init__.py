"""Shared plumbing with no strapdown imports: validation, lazy exports, thread policy, atomic files (floor 0, private)."""
