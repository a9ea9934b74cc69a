"""Soft-sphere discrete element engine (Numba): state, contacts, walls, integration.

Importing it changes no process-wide setting: a run applies Numba's threading settings where it
starts (``pendular.utils.threads.configure``).

The kernels that take most of a step (pair forces, the contact gather, the leapfrog) are
compiled with HOT_KERNEL_FASTMATH: fused multiply-adds and division by a reciprocal (LLVM's
'contract' and 'arcp'), which change results at round-off (about 1e-14 of a force) and keep
them the same for any thread count. Nothing that changes NaN, infinity or signed-zero
handling, or reorders sums: a diverging run is still caught, and sums keep their order
(docs/performance.md gives what they save).
"""

#: Numba ``fastmath`` flags of the hot kernels (module docstring).
HOT_KERNEL_FASTMATH = {"contract", "arcp"}
