"""Studies built on the procedures: campaigns from tables, thesis Chapters 4 and 5, the speed-
accuracy trade-off, the extreme-settings grid, the YADE cross-check.
"""
