"""Small shared utilities used by every layer: errors, atomic file output, progress, lazy
re-exports.

The base of the package: imports nothing else of it.
"""
