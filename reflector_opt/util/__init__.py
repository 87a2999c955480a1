"""Small shared utilities used by every layer: errors, atomic file output, progress, the
worker pools.

The base of the package: imports nothing else of it.
"""
