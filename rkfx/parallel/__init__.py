"""Work over MPI ranks: the partition, ownership and ghosts, rows sent to their owners, and serial work under MPI."""
