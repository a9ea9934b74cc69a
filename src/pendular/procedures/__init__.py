"""Laboratory test procedures on the engine: sample preparation, triaxial, direct tension, the
soil-water characteristic curve, their configurations.
"""
