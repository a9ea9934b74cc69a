"""Soft-sphere discrete element engine (Numba): state, contacts, walls, integration.

Numba's OpenMP threading layer is preferred (lowest launch overhead measured here: 8.0 M
particle-steps/s at 10,000 spheres on 2 threads against 7.5 with TBB and 5.5 with workqueue);
Numba falls back to the next layer where OpenMP is not available.

OpenMP threads wait for the next parallel region by spinning; libgomp's default spin
(GOMP_SPINCOUNT 300,000) made a 2-thread run on a machine with one busy core 6-10 times slower
than on a quiet one (10,000 spheres, dry: 1.0-1.8 against 10.1 M particle-steps/s). Unless the
environment says otherwise, pendular sets GOMP_SPINCOUNT to 5,000 before OpenMP starts: the
same run then does 10.0 M quiet (10.3 M with libgomp's default) and 4.5 M with a busy core
(one thread does 5.6 M there: with other jobs on the machine, one thread per run is still
faster). OPENMP_DEFAULTS holds what was set, so that other programs started from here (YADE)
run with their own.

The kernels that take most of a step (pair forces, the contact gather, the leapfrog) are
compiled with HOT_KERNEL_FASTMATH: fused multiply-adds and division by a reciprocal (LLVM's
'contract' and 'arcp'), which change results at round-off (about 1e-14 of a force) and keep
them the same for any thread count. Nothing that changes NaN, infinity or signed-zero
handling, or reorders sums: a diverging run is still caught, and sums keep their order.
Measured in one run against the strict kernels (10,000 spheres, dry shear): 9-10 % less time
a step on 1 and 2 threads.
"""

import os

import numba

numba.config.THREADING_LAYER_PRIORITY = ["omp", "tbb", "workqueue"]

#: Numba ``fastmath`` flags of the hot kernels (module docstring).
HOT_KERNEL_FASTMATH = {"contract", "arcp"}

#: OpenMP settings pendular applied because the environment had none (name -> value).
OPENMP_DEFAULTS = {}
if not {"GOMP_SPINCOUNT", "OMP_WAIT_POLICY"} & set(os.environ):
    OPENMP_DEFAULTS["GOMP_SPINCOUNT"] = "5000"
    os.environ.update(OPENMP_DEFAULTS)
