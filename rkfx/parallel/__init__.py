"""Work over MPI ranks: the partition, ownership and ghosts, the halo of the explicit step, rows sent to their owners, threads per rank, and serial work under MPI."""
