"""Contributions of every rank's points summed at the owners equal the whole sum.

Run as ``mpiexec -n P python assemble_by_owners.py``; exits non-zero on a mismatch. A
1-D chain of 60 nodes with fields u (2 per node) and p (1 per node) is split into P parts;
each rank integrates "elements" between consecutive nodes whose left node it owns, so its
contributions touch the next rank's first node (a ghost). ``UnknownShare.assemble`` must give
the whole vector at every local entry, and the owned rows of ``row_system`` the whole matrix's.
"""
import dolfinx_solver  # noqa: F401
import numpy as np
import scipy.sparse as sp
from mpi4py import MPI

from rkfx.parallel.ownership import numbering
from rkfx.parallel.unknowns import local_unknowns, row_system, touched_nodes

comm = MPI.COMM_WORLD
n = 60
part = np.arange(n) * comm.size // n  # contiguous parts along the chain
num = numbering(part, comm.size)
rng = np.random.default_rng(7)
values = rng.standard_normal((n - 1, 3, 2))  # per element: a load on each field of its two nodes
blocks = rng.standard_normal((n - 1, 6, 6))


def element_dofs(e):
    nodes = np.array([e, e + 1])
    return np.r_[2 * nodes[0], 2 * nodes[0] + 1, 2 * nodes[1], 2 * nodes[1] + 1, 2 * n + nodes]


def contribution(elements):
    f, rows, cols, data = np.zeros(3 * n), [], [], []
    for e in elements:
        d = element_dofs(e)
        f[d] += np.r_[values[e, 0], values[e, 1], values[e, 2]]
        rows.append(np.repeat(d, 6))
        cols.append(np.tile(d, 6))
        data.append(blocks[e].ravel())
    a = sp.csr_matrix((np.concatenate(data), (np.concatenate(rows), np.concatenate(cols))), shape=(3 * n, 3 * n)) \
        if elements.size else sp.csr_matrix((3 * n, 3 * n))
    return f, a


whole_f, whole_a = contribution(np.arange(n - 1))
mine = np.flatnonzero(part[:-1] == comm.rank)
f, a = contribution(mine)
owned = num.old_of_new[num.ranges[comm.rank]:num.ranges[comm.rank + 1]]
local = local_unknowns(num, np.union1d(touched_nodes((2, 1), n, a), owned), (2, 1), comm)
got = local.share.assemble(local.vector(f))
assert np.allclose(got, local.vector(whole_f), rtol=0, atol=1e-13), "assembled vector"
system = row_system(local.matrix(a), local.share, 0, comm)
dense = system.block.toarray()
glob = local.index[system.rows]  # the whole model's unknown of each owned row
column_of = np.concatenate(comm.allgather(local.index[local.share.owned]))  # global column -> whole unknown
assert np.allclose(dense, whole_a.toarray()[glob][:, column_of], rtol=0, atol=1e-13), "owned rows"
back = system.local_values(system.owned_values(got))
assert np.array_equal(back, got), "local values"
if comm.rank == 0:
    print("ok")
