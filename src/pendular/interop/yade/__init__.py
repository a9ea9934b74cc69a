"""YADE: its text files, and runs of its triaxial driver (scripts/triaxial.py, run by YADE's own
Python, never imported) for the cross-checks. YADE is never a run-time dependency.
"""
