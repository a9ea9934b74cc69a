"""Results on disk: the history file read as xarray, the units schema, output folders, ParaView
series, plots.
"""
