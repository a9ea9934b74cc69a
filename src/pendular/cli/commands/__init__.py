"""One module per ``pendular`` command: ``add_arguments(parser)`` and ``run(args)``.
"""
