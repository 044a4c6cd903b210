"""Work over MPI ranks: ownership of particles, ghost exchange, and serial work under MPI."""
