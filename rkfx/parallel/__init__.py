"""Work over MPI ranks: the partition, ownership and ghosts, rows sent to their owners, threads per rank, and serial work under MPI."""
