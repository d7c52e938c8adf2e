"""Shared plumbing that imports nothing of strapdown: validation, lazy exports, threads, files (floor 0, private)."""
