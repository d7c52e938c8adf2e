"""The release number, one place for the package and every file it writes (private)."""

VERSION = "0.1.0"
