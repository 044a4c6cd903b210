"""The two products of an explicit step, one row or one node at a time: the Voigt strain of a
row of smoothed gradients and the force on a node from its transposed row. The sparse
products of ``rkfx.assembly.smeared_strain`` and the lattice stencils of
``rkfx.assembly.lattice_stencil`` (which must round as they do) share them."""
import numba


@numba.njit(inline="always")
def row_strain(indptr, indices, grad, d, row, out):
    """out[row] = sum_I grad N_I d_I as (eps_xx, eps_yy, gamma_xy), interleaved d."""
    exx = 0.0
    eyy = 0.0
    gxy = 0.0
    for q in range(indptr[row], indptr[row + 1]):
        i = indices[q]
        gx = grad[q, 0]
        gy = grad[q, 1]
        ux = d[2 * i]
        uy = d[2 * i + 1]
        exx += gx * ux
        eyy += gy * uy
        gxy += gy * ux + gx * uy
    out[row, 0] = exx
    out[row, 1] = eyy
    out[row, 2] = gxy


@numba.njit(inline="always")
def node_force(indptr, indices, grad, stress, weight, node, out):
    """out[2 node: 2 node + 2] = sum_rows grad^T stress weight over the node's transposed row."""
    fx = 0.0
    fy = 0.0
    for q in range(indptr[node], indptr[node + 1]):
        ell = indices[q]
        gx = grad[q, 0] * weight[ell]
        gy = grad[q, 1] * weight[ell]
        fx += gx * stress[ell, 0] + gy * stress[ell, 2]
        fy += gy * stress[ell, 1] + gx * stress[ell, 2]
    out[2 * node] = fx
    out[2 * node + 1] = fy


@numba.njit(inline="always")
def particle_average(ptr, fraction, sub, ell, cell):
    """cell[ell] = sum_C (A_C / A_L) e_C over the subcell strains ``sub`` of particle ``ell``,
    which become the differences e_L - e_C in place."""
    a0 = 0.0
    a1 = 0.0
    a2 = 0.0
    for c in range(ptr[ell], ptr[ell + 1]):
        f = fraction[c]
        a0 += f * sub[c, 0]
        a1 += f * sub[c, 1]
        a2 += f * sub[c, 2]
    cell[ell, 0] = a0
    cell[ell, 1] = a1
    cell[ell, 2] = a2
    for c in range(ptr[ell], ptr[ell + 1]):
        sub[c, 0] = a0 - sub[c, 0]
        sub[c, 1] = a1 - sub[c, 1]
        sub[c, 2] = a2 - sub[c, 2]


@numba.njit(inline="always")
def particle_stress(ptr, weight, volume, stress, sub_stress, with_sub, ell):
    """V_L Sigma_L + sum_C eps_p A_C s_C of particle ``ell`` (the stress its subcells share)."""
    t0 = volume[ell] * stress[ell, 0]
    t1 = volume[ell] * stress[ell, 1]
    t2 = volume[ell] * stress[ell, 2]
    if with_sub:
        for c in range(ptr[ell], ptr[ell + 1]):
            t0 += weight[c] * sub_stress[c, 0]
            t1 += weight[c] * sub_stress[c, 1]
            t2 += weight[c] * sub_stress[c, 2]
    return t0, t1, t2


@numba.njit(inline="always")
def particle_load(ptr, fraction, weight, volume, stress, sub_stress, with_sub, ell, out):
    """tau_C = (A_C / A_L) (V_L Sigma_L + sum_C' w_C' s_C') - w_C s_C of the subcells C of
    particle ``ell`` into ``out`` (rows in subcell order)."""
    t0, t1, t2 = particle_stress(ptr, weight, volume, stress, sub_stress, with_sub, ell)
    for c in range(ptr[ell], ptr[ell + 1]):
        f = fraction[c]
        out[c, 0] = f * t0
        out[c, 1] = f * t1
        out[c, 2] = f * t2
        if with_sub:
            out[c, 0] -= weight[c] * sub_stress[c, 0]
            out[c, 1] -= weight[c] * sub_stress[c, 1]
            out[c, 2] -= weight[c] * sub_stress[c, 2]


@numba.njit(inline="always")
def damaged_stress(c, scale, e0, e1, e2, j):
    """Component j of scale C e (the stress of a subcell difference e of a damaged particle)."""
    return scale * (c[j, 0] * e0 + c[j, 1] * e1 + c[j, 2] * e2)
