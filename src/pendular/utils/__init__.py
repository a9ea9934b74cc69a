"""Utilities below the engine: input checks, atomic writes, file integrity, Ctrl-C handling,
Numba's threading settings.
"""
