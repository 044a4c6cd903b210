"""RK approximation: kernels, neighbour search, shape functions and gradients, diffraction round cracks; sparse rows."""
