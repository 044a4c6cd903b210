"""Integration rules as sparse rows of shape functions and gradients: Gauss, DNI, SCNI, MSCNI; error norms."""
