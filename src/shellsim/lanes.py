"""Lanes: the compiled kernels evaluate LANES elements together, the element index the
innermost axis of every work array, so each arithmetic line runs over a contiguous
vector of elements and compiles to packed SIMD (the grouping of production explicit
codes, e.g. OpenRadioss' MVSIZ). A work array of shape (..., G) holds one value per lane
(G = LANES).

LANES = 16 was measured on the point geometry alone (50 points of an element, an AVX-512
core, helpers inlined): 8.5 microseconds per element one element at a time, 5.1 with 8
lanes, 1.2 with 16, 1.1 with 32; 16 keeps a group's work arrays (about 0.4 MB) within the
core's L2 cache. Meshes of fewer than 16 elements pay for the spare lanes.

The constant sits at the bottom of the package: the element kernels, the 3 x 3 algebra
and every material law size their work arrays with it.
"""

#: Elements per group (a compile-time constant of every kernel).
LANES = 16
