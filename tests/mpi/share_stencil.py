"""A rank's share of an MSCNI operator on a uniform grid with a slit evaluates its rows as
lattice stencils over its box, and its strains, forces and damaged forces are the whole
operator's bit for bit. Prints ``coverage <rows> <nodes>`` of the share's stencils (the least
over the ranks) and exits non-zero on any difference.

    mpiexec -n 3 python tests/mpi/share_stencil.py
"""
import dolfinx_solver  # noqa: F401  (before mpi4py)
import numpy as np
from mpi4py import MPI

from rkfx.approximation.diffraction import cracks
from rkfx.approximation.shape_functions import rk_approximation
from rkfx.assembly.local_strain import local_smeared_strain
from rkfx.assembly.smeared_strain import StrainRecipe
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.particles import graded
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.parallel.partition import rcb

SLIT = ((0.0, 0.25), (0.5, 0.25))


def main() -> None:
    comm = MPI.COMM_WORLD
    xs, ys = np.linspace(0.0, 1.0, 40), np.linspace(0.0, 1.0, 43)
    p = graded(xs, ys)
    rk = rk_approximation(p.x, p.spacing, 2.0, cracks=cracks([np.array(SLIT)], [(False, True)]))
    recipe = StrainRecipe(p, rk, grid_domains(xs, ys, [SLIT]), 1.0)
    whole = recipe.build()
    local = local_smeared_strain(recipe, rcb(p.x, comm.size), comm)
    st = local.stencil
    assert st is not None, "the share has no stencils"
    mine, s = local.points, whole.stabilization
    rows = np.concatenate([np.arange(s.ptr[k], s.ptr[k + 1]) for k in mine])
    rng = np.random.default_rng(0)
    n = p.num_nodes
    d = rng.standard_normal(2 * n)
    stress, sub_stress = rng.standard_normal((n, 3)), rng.standard_normal((len(s.owner), 3))
    damage = rng.uniform(0.0, 1.0, n)
    c = ElasticMaterial(2.0e11, 0.3).D()
    (e, sub), (e0, sub0) = local.strains(d[local.dofs]), whole.strains(d)
    checks = {
        "strains": np.array_equal(e, e0[mine]) and np.array_equal(sub, sub0[rows]),
        "force": np.array_equal(local.force(stress[mine]), whole.force(stress)[local.dofs]),
        "force with subcell stresses": np.array_equal(local.force(stress[mine], sub_stress[rows]),
                                                      whole.force(stress, sub_stress)[local.dofs]),
        "damaged force": np.array_equal(local.damaged_force(stress[mine], sub.copy(), c, damage[mine]),
                                        whole.damaged_force(stress, sub0.copy(), c, damage)[local.dofs]),
    }
    failed = [name for name, ok in checks.items() if not ok]
    assert not failed, f"rank {comm.rank}: {', '.join(failed)} differ from the whole operator's"
    cover = comm.allreduce(min(st.coverage), op=MPI.MIN)
    if comm.rank == 0:
        print(f"coverage {cover:.3f}")


if __name__ == "__main__":
    main()
