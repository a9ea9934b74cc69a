"""Soft-sphere discrete element engine (Numba): state, contacts, walls, integration."""
