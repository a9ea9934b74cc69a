"""Other programs' formats and runs.
"""
