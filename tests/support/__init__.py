"""Helpers the tests share that are not fixtures (tests/conftest.py holds those): imported by
test modules and by the scripts they run in processes of their own, never a test module."""
